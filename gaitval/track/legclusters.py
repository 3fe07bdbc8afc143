"""leg_tracker's scan clustering and cluster features, compiled with numba (issue 36).

A re-implementation of angusleigh/leg_tracker (BSD-3, Leigh et al., ICRA 2015; snapshot
commit e6cbb2b of its public repository), so that a leg classifier trained the way
leg_tracker trains its random forest sees the same 17 numbers per cluster:

* :func:`cluster_scan` — ``laser_processor.cpp``: ``Sample::Extract`` (a return is a
  sample when ``range_min < r < range_max``, lines 41–56), ``ScanProcessor::
  splitConnected`` (lines 123–170: breadth-first, a sample joins a cluster when it is
  less than ``thresh`` from a sample of it, the search per queued sample limited to
  indices below ``index + (int)(asin(thresh/range)/angle_increment)``) and
  ``removeLessThan`` (lines 105–121).  leg_tracker's values: ``cluster_dist_euclid`` =
  0.13 m, ``min_points_per_cluster`` = 3 (``detect_leg_clusters.cpp`` lines 76–77).
* :func:`cluster_features` — ``cluster_features.cpp``, ``calcClusterFeatures`` (the line
  of each feature beside it below), in leg_tracker's order (lines 296–319)::

      0 n  1 std  2 avg_median_dev  3 width  4 linearity  5 circularity  6 radius (= 0)
      7 boundary_length  8 boundary_regularity  9 mean_curvature  10 ang_diff  11 iav
      12 std_iav  13 distance  14 distance/n  15 occluded_right  16 occluded_left

  The C++ computes in single precision (``float``); this computes in double.  One
  deliberate difference: Heron's product ``s(s−a)(s−b)(s−c)`` is clamped at 0 before its
  square root (likewise the variances under the square roots of the boundary regularity
  and of std_iav), where the C++ gets NaN from rounding, e.g. on three collinear points (a
  NaN feature has no defined path in a tree).  The linearity's SVD and the circle fit use
  numpy's SVD / least squares (OpenCV's ``cv::SVD::compute`` and ``cv::solve(...,
  DECOMP_SVD)`` give the same minimum-norm solution).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: leg_tracker's feature names, in its order (``cluster_features.cpp`` lines 278–301)
FEATURES = ("n_points", "std", "avg_median_dev", "width", "linearity", "circularity",
            "radius", "boundary_length", "boundary_regularity", "mean_curvature",
            "ang_diff", "iav", "std_iav", "distance", "distance_per_point",
            "occluded_right", "occluded_left")
N_FEATURES = len(FEATURES)


@njit(cache=True)
def cluster_scan(ranges, angle_min, angle_increment, range_min, range_max, thresh,
                 min_points):
    """Cluster labels per beam (−1: no sample or a cluster of fewer than ``min_points``),
    clusters numbered 0, 1, … in the order leg_tracker's ``splitConnected`` finds them
    (by their first index).  ``ranges``: one scan, NaN for no return."""
    n = ranges.shape[0]
    valid = np.zeros(n, dtype=np.bool_)
    xs = np.empty(n)
    ys = np.empty(n)
    for i in range(n):                      # Sample::Extract (laser_processor.cpp 41-56)
        r = ranges[i]
        a = angle_min + i * angle_increment
        xs[i] = math.cos(a) * r
        ys[i] = math.sin(a) * r
        valid[i] = (r > range_min) and (r < range_max)
    rest = np.flatnonzero(valid)            # the SampleSet, ordered by index
    taken = np.zeros(n, dtype=np.bool_)
    label = np.full(n, -1, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    n_clusters = 0
    first = 0                               # rest[:first] are all taken
    for s0 in rest:                         # splitConnected (laser_processor.cpp 123-170, the test on line 151)
        if taken[s0]:
            continue
        taken[s0] = True
        qn = 1
        queue[0] = s0
        q = 0
        while q < qn:
            sq = queue[q]
            ratio = thresh / ranges[sq]
            if ratio <= 1.0:
                expand = int(math.asin(ratio) / angle_increment)
                limit = sq + expand
            else:
                limit = -1                  # C++: (int)NaN, no sample below it
            while first < rest.shape[0] and taken[rest[first]]:
                first += 1
            for u in range(first, rest.shape[0]):
                s = rest[u]
                if s >= limit:
                    break
                if taken[s]:
                    continue
                dx = xs[sq] - xs[s]
                dy = ys[sq] - ys[s]
                if math.sqrt(dx * dx + dy * dy) < thresh:
                    taken[s] = True
                    queue[qn] = s
                    qn += 1
            q += 1
        if qn >= min_points:                # removeLessThan (laser_processor.cpp 105-121)
            for j in range(qn):
                label[queue[j]] = n_clusters
            n_clusters += 1
    return label, n_clusters


@njit(cache=True)
def _angle(ax, ay, bx, by):
    """leg_tracker's angle at the middle point: atan2 of cross and dot over |b|², in
    [0, 2π) (cluster_features.cpp 226-232, 274-280)."""
    lb = bx * bx + by * by
    A = (ax * bx + ay * by) / lb
    B = (ax * by - ay * bx) / lb
    th = math.atan2(B, A)
    if th < 0:
        th += 2 * math.pi
    return th


@njit(cache=True)
def _cluster_points(idx, ranges, angle_min, angle_increment):
    n = idx.shape[0]
    x = np.empty(n)
    y = np.empty(n)
    r = np.empty(n)
    for j in range(n):
        i = idx[j]
        a = angle_min + i * angle_increment
        r[j] = ranges[i]
        x[j] = math.cos(a) * ranges[i]
        y[j] = math.sin(a) * ranges[i]
    return x, y, r


@njit(cache=True)
def _spread(x, y):
    """Means, distance of the median point, std and average deviation from the median
    (cluster_features.cpp 43-79)."""
    n = x.shape[0]
    x_mean = x.mean()
    y_mean = y.mean()
    xs = np.sort(x)
    ys = np.sort(y)
    x_median = 0.5 * (xs[(n - 1) // 2] + xs[n // 2])
    y_median = 0.5 * (ys[(n - 1) // 2] + ys[n // 2])
    distance = math.sqrt(x_median * x_median + y_median * y_median)        # cpp 66
    sum_std = 0.0
    sum_med = 0.0
    for j in range(n):
        sum_std += (x[j] - x_mean) ** 2 + (y[j] - y_mean) ** 2
        sum_med += math.sqrt((x[j] - x_median) ** 2 + (y[j] - y_median) ** 2)
    return x_mean, y_mean, distance, math.sqrt(sum_std / (n - 1.0)), sum_med / n


@njit(cache=True)
def _occluded(idx, r, ranges, range_min, range_max):
    """Occluded left / right: the neighbouring beams (cpp 81-120)."""
    n = idx.shape[0]
    occ_left = 1.0
    occ_right = 1.0
    prev_i = idx[0] - 1
    if prev_i >= 0:
        pr = ranges[prev_i]
        if pr > range_min and pr < range_max:
            if r[0] < pr or pr < 0.01:
                occ_left = 0.0
    next_i = idx[n - 1] + 1
    if next_i < ranges.shape[0]:
        nr = ranges[next_i]
        if nr > range_min and nr < range_max:
            if r[n - 1] < nr or nr < 0.01:
                occ_right = 0.0
    return occ_left, occ_right


@njit(cache=True)
def _linearity(x, y, x_mean, y_mean):
    """The squared second singular value of the centred points (cpp 128-151): Σ over
    rot_points' second column² = σ₂², the smaller eigenvalue of the scatter matrix."""
    sxx = 0.0
    sxy = 0.0
    syy = 0.0
    for j in range(x.shape[0]):
        sxx += (x[j] - x_mean) ** 2
        sxy += (x[j] - x_mean) * (y[j] - y_mean)
        syy += (y[j] - y_mean) ** 2
    half = 0.5 * (sxx - syy)
    return max(0.5 * (sxx + syy) - math.sqrt(half * half + sxy * sxy), 0.0)


@njit(cache=True)
def _circularity(x, y):
    """Least-squares circle, Σ(r_c − |p − c|)² (cpp 154-182)."""
    n = x.shape[0]
    A = np.empty((n, 3))
    B = np.empty(n)
    for j in range(n):
        A[j, 0] = -2.0 * x[j]
        A[j, 1] = -2.0 * y[j]
        A[j, 2] = 1.0
        B[j] = -x[j] * x[j] - y[j] * y[j]
    sol = np.linalg.lstsq(A, B)[0]
    xc, yc = sol[0], sol[1]
    rc = math.sqrt(xc * xc + yc * yc - sol[2]) if xc * xc + yc * yc - sol[2] >= 0 else np.nan
    circularity = 0.0
    for j in range(n):
        circularity += (rc - math.sqrt((xc - x[j]) ** 2 + (yc - y[j]) ** 2)) ** 2
    return circularity


@njit(cache=True)
def _boundary(x, y):
    """Boundary length and regularity, mean curvature, mean angular difference (cpp
    188-252)."""
    n = x.shape[0]
    mean_curvature = 0.0
    boundary_length = 0.0
    last_seg = 0.0
    sum_reg_sq = 0.0
    ang_diff = 0.0
    for j in range(n - 2):                  # right = j, mid = j + 1, left = j + 2
        mlx = x[j + 2] - x[j + 1]
        mly = y[j + 2] - y[j + 1]
        L_ml = math.sqrt(mlx * mlx + mly * mly)
        mrx = x[j] - x[j + 1]
        mry = y[j] - y[j + 1]
        L_mr = math.sqrt(mrx * mrx + mry * mry)
        lrx = x[j + 2] - x[j]
        lry = y[j + 2] - y[j]
        L_lr = math.sqrt(lrx * lrx + lry * lry)
        boundary_length += L_mr
        sum_reg_sq += L_mr * L_mr
        last_seg = L_ml
        th = _angle(mlx, mly, mrx, mry)
        ang_diff += th / n
        s = 0.5 * (L_ml + L_mr + L_lr)
        heron = s * (s - L_ml) * (s - L_mr) * (s - L_lr)
        area = math.sqrt(heron) if heron > 0 else 0.0     # clamped (module notes)
        if th > 0:
            mean_curvature += 4 * area / (L_ml * L_mr * L_lr * n)
        else:
            mean_curvature -= 4 * area / (L_ml * L_mr * L_lr * n)
    boundary_length += last_seg
    sum_reg_sq += last_seg * last_seg
    reg = (sum_reg_sq - boundary_length ** 2 / n) / (n - 1)
    boundary_regularity = math.sqrt(reg) if reg > 0 else 0.0               # cpp 252
    return boundary_length, boundary_regularity, mean_curvature, ang_diff


@njit(cache=True)
def _inscribed_angle(x, y):
    """Inscribed angle variation: first, each middle point, last (cpp 255-290)."""
    n = x.shape[0]
    sum_iav = 0.0
    sum_iav_sq = 0.0
    for j in range(1, n - 1):
        th = _angle(x[0] - x[j], y[0] - y[j], x[n - 1] - x[j], y[n - 1] - y[j])
        sum_iav += th
        sum_iav_sq += th * th
    v = (sum_iav_sq - sum_iav ** 2 / n) / (n - 1)
    return sum_iav / n, math.sqrt(v) if v > 0 else 0.0


@njit(cache=True)
def cluster_features(idx, ranges, angle_min, angle_increment, range_min, range_max):
    """The 17 features of one cluster (beam indices ``idx``, increasing) of one scan."""
    n = idx.shape[0]
    x, y, r = _cluster_points(idx, ranges, angle_min, angle_increment)
    x_mean, y_mean, distance, std, avg_median_dev = _spread(x, y)
    occ_left, occ_right = _occluded(idx, r, ranges, range_min, range_max)
    width = math.sqrt((x[0] - x[n - 1]) ** 2 + (y[0] - y[n - 1]) ** 2)       # cpp 125
    boundary_length, boundary_regularity, mean_curvature, ang_diff = _boundary(x, y)
    iav, std_iav = _inscribed_angle(x, y)
    out = np.empty(17)
    out[0] = n                      # cpp 296
    out[1] = std                    # cpp 297
    out[2] = avg_median_dev         # cpp 298
    out[3] = width                  # cpp 301
    out[4] = _linearity(x, y, x_mean, y_mean)   # cpp 302
    out[5] = _circularity(x, y)     # cpp 303
    out[6] = 0.0                    # radius, cpp 186 and 304
    out[7] = boundary_length        # cpp 305
    out[8] = boundary_regularity    # cpp 306
    out[9] = mean_curvature         # cpp 307
    out[10] = ang_diff              # cpp 308
    out[11] = iav                   # cpp 312
    out[12] = std_iav               # cpp 313
    out[13] = distance              # cpp 316
    out[14] = distance / n          # cpp 317
    out[15] = occ_right             # cpp 318
    out[16] = occ_left              # cpp 319
    return out


@njit(cache=True)
def scan_clusters(ranges, angle_min, angle_increment, range_min, range_max, thresh,
                  min_points):
    """Every cluster of one scan: (centroids (C, 2) — leg_tracker's ``getPosition``, the
    mean of the points —, features (C, 17))."""
    label, nc = cluster_scan(ranges, angle_min, angle_increment, range_min, range_max,
                             thresh, min_points)
    cen = np.zeros((nc, 2))
    feats = np.zeros((nc, 17))
    for c in range(nc):
        idx = np.flatnonzero(label == c)
        for i in idx:
            a = angle_min + i * angle_increment
            cen[c, 0] += math.cos(a) * ranges[i] / idx.shape[0]
            cen[c, 1] += math.sin(a) * ranges[i] / idx.shape[0]
        feats[c] = cluster_features(idx, ranges, angle_min, angle_increment, range_min,
                                    range_max)
    return cen, feats


def all_clusters(scans, thresh: float = 0.13, min_points: int = 3):
    """Per scan of a :class:`~gaitval.types.ScanSeries`: (centroids, features) of every
    cluster (leg_tracker's ``cluster_dist_euclid`` 0.13 m, ``min_points_per_cluster`` 3)."""
    a0, inc = float(scans.angle_min), float(scans.angle_increment)
    rmin = float(getattr(scans, "range_min", 0.0) or 0.0)
    rmax = float(scans.range_max)
    R = np.ascontiguousarray(scans.ranges, dtype=float)
    return [scan_clusters(R[k], a0, inc, rmin, rmax, float(thresh), int(min_points))
            for k in range(R.shape[0])]
