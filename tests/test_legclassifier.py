"""leg_tracker's clustering, cluster features and leg forest as re-implemented in gaitval
(gaitval/track/legclusters.py, legforest.py, appearance.py; issue 36)."""
from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from gaitval.track.appearance import APPEARANCES
from gaitval.track.legclusters import (FEATURES, cluster_features, cluster_scan,
                                       scan_clusters)
from gaitval.track.legforest import FORESTS, LegForest, load_forest

INC = math.radians(0.5)
A0 = -math.pi / 2


def _scan(points_by_beam, n=361):
    r = np.full(n, np.nan)
    for i, v in points_by_beam.items():
        r[i] = v
    return r


def _cpp_features(x, y, r, prev_r, next_r, rmin=0.03, rmax=30.0):
    """cluster_features.cpp, written out line by line a second time (plain loops and
    numpy's SVD / lstsq, as OpenCV's cv::SVD::compute and cv::solve(DECOMP_SVD))."""
    n = len(x)
    xm, ym = np.mean(x), np.mean(y)
    xs, ys = sorted(x), sorted(y)
    xmed = 0.5 * (xs[(n - 1) // 2] + xs[n // 2])
    ymed = 0.5 * (ys[(n - 1) // 2] + ys[n // 2])
    distance = math.hypot(xmed, ymed)
    std = math.sqrt(sum((x - xm) ** 2 + (y - ym) ** 2) / (n - 1))
    amd = float(np.mean(np.hypot(x - xmed, y - ymed)))
    occ_l = 1.0
    if prev_r is not None and rmin < prev_r < rmax and (r[0] < prev_r or prev_r < 0.01):
        occ_l = 0.0
    occ_r = 1.0
    if next_r is not None and rmin < next_r < rmax and (r[-1] < next_r or next_r < 0.01):
        occ_r = 0.0
    width = math.hypot(x[0] - x[-1], y[0] - y[-1])
    P = np.c_[x - xm, y - ym]
    U, W, _ = np.linalg.svd(P, full_matrices=False)
    linearity = float(np.sum((U * W)[:, 1] ** 2))
    A = np.c_[-2 * x, -2 * y, np.ones(n)]
    sol = np.linalg.lstsq(A, -x ** 2 - y ** 2, rcond=None)[0]
    rc = math.sqrt(sol[0] ** 2 + sol[1] ** 2 - sol[2])
    circ = float(np.sum((rc - np.hypot(sol[0] - x, sol[1] - y)) ** 2))
    bl = reg = ang = curv = last = 0.0
    for j in range(n - 2):
        ml = np.array([x[j + 2] - x[j + 1], y[j + 2] - y[j + 1]])
        mr = np.array([x[j] - x[j + 1], y[j] - y[j + 1]])
        lr = np.array([x[j + 2] - x[j], y[j + 2] - y[j]])
        Lml, Lmr, Llr = map(np.linalg.norm, (ml, mr, lr))
        bl += Lmr
        reg += Lmr ** 2
        last = Lml
        th = math.atan2((ml[0] * mr[1] - ml[1] * mr[0]) / Lmr ** 2, ml @ mr / Lmr ** 2)
        th = th + 2 * math.pi if th < 0 else th
        ang += th / n
        s = 0.5 * (Lml + Lmr + Llr)
        area = math.sqrt(max(s * (s - Lml) * (s - Lmr) * (s - Llr), 0.0))
        curv += (1 if th > 0 else -1) * 4 * area / (Lml * Lmr * Llr * n)
    bl += last
    reg += last ** 2
    breg = math.sqrt((reg - bl ** 2 / n) / (n - 1))
    ths = []
    for j in range(1, n - 1):
        a = np.array([x[0] - x[j], y[0] - y[j]])
        b = np.array([x[-1] - x[j], y[-1] - y[j]])
        th = math.atan2((a[0] * b[1] - a[1] * b[0]) / (b @ b), a @ b / (b @ b))
        ths.append(th + 2 * math.pi if th < 0 else th)
    iav = sum(ths) / n
    std_iav = math.sqrt((sum(t * t for t in ths) - sum(ths) ** 2 / n) / (n - 1))
    return [n, std, amd, width, linearity, circ, 0.0, bl, breg, curv, ang, iav, std_iav,
            distance, distance / n, occ_r, occ_l]


def _leg_scan(centre=(1.5, 0.2), radius=0.055, n=361):
    """Beams hitting a circle (a leg) in front of a far wall."""
    r = np.full(n, np.nan)
    for i in range(n):
        a = A0 + i * INC
        u = np.array([math.cos(a), math.sin(a)])
        c = np.asarray(centre)
        b = u @ c
        disc = b * b - (c @ c - radius ** 2)
        r[i] = b - math.sqrt(disc) if disc >= 0 else 4.0
    return r


def test_features_follow_the_cpp_definitions_on_a_synthetic_leg():
    """Every one of the 17 features of a leg-like arc equals the C++ definition written out
    a second time (_cpp_features), and a few by hand: a circle's mean curvature is
    (n−2)/n · 1/radius, its circle fit is exact (circularity 0), radius is always 0."""
    r = _leg_scan()
    label, nc = cluster_scan(r, A0, INC, 0.03, 30.0, 0.13, 3)
    legs = [c for c in range(nc) if np.nanmax(r[label == c]) < 3]
    assert len(legs) == 1
    idx = np.flatnonzero(label == legs[0])
    got = cluster_features(idx, r, A0, INC, 0.03, 30.0)
    a = A0 + idx * INC
    x, y = np.cos(a) * r[idx], np.sin(a) * r[idx]
    want = _cpp_features(x, y, r[idx], r[idx[0] - 1], r[idx[-1] + 1])
    assert len(got) == len(FEATURES) == 17
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    n = len(idx)
    assert got[0] == n and got[6] == 0.0
    assert got[5] == pytest.approx(0.0, abs=1e-12)                    # exact circle
    assert got[9] == pytest.approx((n - 2) / n / 0.055, rel=1e-6)     # mean curvature
    assert got[13] == pytest.approx(math.hypot(x[n // 2], y[n // 2]), rel=0.01)
    assert got[15] == 0.0 and got[16] == 0.0       # the wall behind: not occluded


def test_occlusion_and_an_irregular_cluster():
    """A random wiggly cluster (no closed form) still equals the C++ definition; a nearer
    return next to it makes it occluded on that side, no return (NaN) does too
    (Sample::Extract returns NULL: the feature stays 1)."""
    rng = np.random.default_rng(3)
    r = _scan({})
    idx = np.arange(100, 108)
    r[idx] = 2.0 + rng.normal(0, 0.01, len(idx))
    r[99] = 1.0                                    # nearer on the left: occluded left
    got = cluster_features(idx, r, A0, INC, 0.03, 30.0)
    a = A0 + idx * INC
    want = _cpp_features(np.cos(a) * r[idx], np.sin(a) * r[idx], r[idx], r[99], r[108])
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert got[16] == 1.0 and got[15] == 1.0       # left nearer → 1; right NaN → 1
    r[99] = 5.0
    assert cluster_features(idx, r, A0, INC, 0.03, 30.0)[16] == 0.0


def test_clusters_join_below_the_distance_and_small_ones_go():
    """splitConnected: returns less than 0.13 m apart join; a gap of more splits; a group
    of 2 returns is removed (min 3); centroids are the means of the returns."""
    r = _scan({i: 2.0 for i in range(10, 16)} | {i: 2.0 for i in range(30, 33)}
              | {50: 2.0, 51: 2.0})
    label, nc = cluster_scan(r, A0, INC, 0.03, 30.0, 0.13, 3)
    assert nc == 2
    assert set(np.flatnonzero(label == 0)) == set(range(10, 16))
    assert set(np.flatnonzero(label == 1)) == {30, 31, 32}
    assert (label[50:52] == -1).all()
    cen, f = scan_clusters(r, A0, INC, 0.03, 30.0, 0.13, 3)
    a = A0 + np.arange(30, 33) * INC
    assert cen[1] == pytest.approx([2 * np.cos(a).mean(), 2 * np.sin(a).mean()])
    # a step in range of 0.2 m between neighbouring beams splits the cluster
    r2 = _scan({i: 2.0 for i in range(10, 16)} | {i: 2.2 for i in range(16, 20)})
    assert cluster_scan(r2, A0, INC, 0.03, 30.0, 0.13, 3)[1] == 2


def test_forest_votes_are_the_share_of_trees_voting_leg():
    """LegForest (numba, from the trees' arrays) gives each sample the fraction of trees
    whose leaf says "leg", as OpenCV's getVotes; checked against scikit-learn's own
    trees on data it has not seen."""
    from sklearn.ensemble import RandomForestClassifier
    rng = np.random.default_rng(0)
    X = rng.normal(size=(400, 17))
    y = np.where(X[:, 1] + 0.5 * X[:, 4] + rng.normal(0, 0.5, 400) > 0, 1, -1)
    m = RandomForestClassifier(n_estimators=15, max_depth=20, min_samples_split=2,
                               max_features=2, random_state=0).fit(X, y)
    f = LegForest.from_sklearn(m)
    Xt = rng.normal(size=(200, 17))
    want = np.mean([m.classes_[t.predict(Xt).astype(int)] == 1 for t in m.estimators_],
                   axis=0)
    np.testing.assert_array_equal(f.votes(Xt), want)
    assert f.n_trees == 15


def test_shipped_forests_load_and_separate_a_leg_from_a_wall():
    """The four shipped forests (leg_tracker's recipe: 100 trees) give a leg-like arc a
    higher P(leg) than a flat wall."""
    r = _leg_scan()
    cen, feats = scan_clusters(r, A0, INC, 0.03, 30.0, 0.13, 3)
    leg = int(np.argmin(np.hypot(cen[:, 0], cen[:, 1])))
    for name in FORESTS:
        f = load_forest(name)
        assert f.n_trees == 100
        p = f.votes(feats)
        assert ((0 <= p) & (p <= 1)).all()
        assert p[leg] > p[1 - leg], (name, p)


def test_leg_forest_confidence_rule():
    """joint_leg_tracker.py's rule: c ← 0.95 c + 0.05 p per observed leg while tentative;
    the pair ends when a leg's c < 0.1; confirmed, the person's c starts at the legs' mean
    and follows the mean score of the legs seen; a pair scoring < 0.1 is not born."""
    look = APPEARANCES.build({"name": "leg_forest"})
    assert not look.admits(0.05, 0.9) and look.admits(0.1, 0.9)
    p = SimpleNamespace(look=look.start(0.2, 0.9), zp=[0.0, None])
    look.update(p)
    assert p.look["legs"] == pytest.approx([0.19, 0.9])
    n = 0
    while look.keeps(p):
        look.update(p)
        n += 1
    # 0.2·0.95^k < 0.1 first at k = 14 (the update above was the first)
    assert n + 1 == math.ceil(math.log(0.5) / math.log(0.95))
    q = SimpleNamespace(look=look.start(0.4, 0.6), zp=[None, None])
    look.confirmed(q)
    assert q.look["person"] == pytest.approx(0.5)
    q.zp = [0.0, 1.0]
    look.update(q)
    assert q.look["person"] == pytest.approx(0.95 * 0.5 + 0.05 * 0.5)
    q.zp = [None, None]
    look.update(q)                                  # nothing seen: unchanged
    assert q.look["person"] == pytest.approx(0.5)
    none = APPEARANCES.build("none")
    assert none.keeps(q) and none.admits(0.0, 0.0)


def test_an_unknown_forest_is_one_clear_error(tmp_path):
    from gaitval.errors import FileFormatError
    with pytest.raises(FileFormatError, match="leg classifier .* not found"):
        load_forest(str(tmp_path / "absent.npz"))
