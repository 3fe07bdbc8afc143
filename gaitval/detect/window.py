"""Seed 002 §II leg detector: observation window, distance grouping, K-means, circle fit.

Per scan (seed002 §II): the raw ranges are converted from polar to Cartesian coordinates;
only the points inside a rectangular *observation window* are kept; they are split into
groups by a distance threshold; groups with fewer than ``min_points`` points are deleted;
K-means (k = 2) splits the remaining points into two legs; a circle fitted to each cluster
gives the leg centre, the observation of the Kalman filter.

The paper leaves these choices open (seed 002 checklist GAPs); gaitval's rules:

Window
    At the first scan of a track, and whenever the tracker has no prediction (initialisation,
    re-initialisation), the window is the predefined rectangle ``window_x_m`` ×
    ``window_y_m`` in the sensor frame (x forward from the laser, towards the user; y left):
    by default 0.10–1.00 m ahead and ±0.40 m to the side, the space a rollator user's shanks
    occupy behind the frame.  The near edge keeps the rollator's own frame out (its rear
    tubes are within a few centimetres of the laser).  Afterwards the window is the smallest
    rectangle that holds both predicted legs, each widened per axis by ``n_sigma`` standard
    deviations of its innovation covariance (√S_xx, √S_yy, seed000 eq. (12)) plus half a
    leg width, clipped to the predefined rectangle: it grows while the legs are predicted
    only, never beyond where a user can stand.  ``n_sigma`` = 3 (99.7 % per axis).
Grouping
    Consecutive in-window points (beam order) more than ``group_gap_leg_widths`` · w_l
    apart start a new group: 0.5 w_l, the edge threshold of seed000 eq. (6).
Small groups
    Fewer than ``min_points`` = 5 points: three points fix a circle exactly, five leave
    two redundant for the fit.
K-means
    scikit-learn ``KMeans(n_clusters=2, n_init=1, random_state=0)`` on the remaining
    points' (x, y) (one k-means++ start, scikit-learn's own default for that
    initialisation; fixed seed: same scan → same clusters).  Which cluster is the left leg
    is the tracker's association (each cluster goes to the predicted leg it is nearest to,
    seed 002 §II's "labeled as left/right").  scikit-learn's thread-pool set-up costs
    ~20 ms per call; callers tracking whole trials wrap the run in
    ``threadpoolctl.threadpool_limits(1)`` (≈ 2 ms per call then).
Circle fit
    Algebraic least squares (Kasa 1976) per cluster.  A fit whose radius is outside
    [0.25, 1.0]·w_l or whose centre is not behind the points (seen from the laser) is
    replaced by the known-radius placement: the points' centroid moved away from the laser
    by (π/4)·w_l/2, the mean depth of a circle's visible half sampled evenly across its width.
One leg, one observation
    Two cluster centres closer than ``min_leg_widths`` · w_l (0.7) are one leg cut in two
    (one leg hidden, or the legs together): one circle is fitted to all points instead.

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017.
Kasa I. A circle fitting procedure and its error analysis. IEEE Trans. Instrum. Meas. 1976,
25(1), 8-14.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from gaitval.detect.base import DETECTORS, WindowedDetector
from gaitval.errors import ConfigError

_NO_OBS = (np.zeros((0, 2)), [])


def window_box(predicted, leg_width_m: float, base: tuple, n_sigma: float) -> tuple:
    """The observation window ``(x_lo, x_hi, y_lo, y_hi)`` (module notes, seed002 §II).

    Parameters
    ----------
    predicted : None or sequence of ((x, y), S)
        Predicted legs and their 2×2 innovation covariances; None → ``base``.
    leg_width_m : float
    base : (x_lo, x_hi, y_lo, y_hi)
        The predefined window.
    n_sigma : float
    """
    if predicted is None:
        return base
    r = 0.5 * leg_width_m
    xs, ys = [], []
    for (x, y), S in predicted:
        hx = n_sigma * math.sqrt(max(float(S[0][0]), 0.0)) + r
        hy = n_sigma * math.sqrt(max(float(S[1][1]), 0.0)) + r
        xs += [x - hx, x + hx]
        ys += [y - hy, y + hy]
    return (max(min(xs), base[0]), min(max(xs), base[1]),
            max(min(ys), base[2]), min(max(ys), base[3]))


def split_groups(pts: np.ndarray, gap_m: float) -> list[np.ndarray]:
    """Consecutive points (beam order) split where neighbours are more than ``gap_m``
    apart."""
    if len(pts) == 0:
        return []
    jump = np.hypot(*np.diff(pts, axis=0).T) > gap_m
    return np.split(pts, np.flatnonzero(jump) + 1)


def fit_circle(pts: np.ndarray) -> tuple[float, float, float]:
    """Kasa's algebraic circle fit: ``x² + y² = 2a x + 2b y + c`` → centre (a, b),
    radius √(c + a² + b²).  NaN radius when the points do not determine a circle."""
    A = np.column_stack([2.0 * pts[:, 0], 2.0 * pts[:, 1], np.ones(len(pts))])
    rhs = (pts * pts).sum(axis=1)
    sol, *_ = np.linalg.lstsq(A, rhs, rcond=None)
    a, b, c = sol
    r2 = c + a * a + b * b
    return float(a), float(b), float(math.sqrt(r2)) if r2 > 0 else float("nan")


def leg_centre(pts: np.ndarray, leg_width_m: float) -> tuple[float, float]:
    """Leg centre of one cluster: the circle fit, or the known-radius placement when the
    fit is implausible (module notes)."""
    a, b, r = fit_circle(pts) if len(pts) >= 3 else (0.0, 0.0, float("nan"))
    m = pts.mean(axis=0)
    rng_m = math.hypot(m[0], m[1])
    if (np.isfinite(r) and 0.25 * leg_width_m <= r <= leg_width_m
            and math.hypot(a, b) > rng_m):
        return a, b
    push = 0.25 * math.pi * 0.5 * leg_width_m                 # (π/4)·ρ behind the centroid
    return float(m[0] * (1.0 + push / rng_m)), float(m[1] * (1.0 + push / rng_m))


@DETECTORS.register("rollator_window")
class RollatorWindowDetector(WindowedDetector):
    """Window → groups → K-means (k = 2) → circle fits (seed 002 §II; module notes).

    Parameters
    ----------
    window_x_m, window_y_m : (float, float)
        The predefined window in the sensor frame (m).
    n_sigma : float
        Half-size of the window around a predicted leg, in innovation standard deviations
        (plus half a leg width).
    group_gap_leg_widths : float
        Distance between consecutive points that starts a new group, in leg widths.
    min_points : int
        Groups with fewer points are deleted.
    min_leg_widths : float
        Two cluster centres closer than this (in leg widths) are one leg.
    n_init, random_state : int
        scikit-learn ``KMeans`` parameters (restarts, seed): same scan → same clusters.
    """

    def __init__(self, window_x_m=(0.10, 1.00), window_y_m=(-0.40, 0.40),
                 n_sigma: float = 3.0, group_gap_leg_widths: float = 0.5,
                 min_points: int = 5, min_leg_widths: float = 0.7, n_init: int = 1,
                 random_state: int = 0):
        x0, x1 = (float(v) for v in window_x_m)
        y0, y1 = (float(v) for v in window_y_m)
        if not (x0 < x1 and y0 < y1):
            raise ConfigError(f"rollator_window: empty predefined window x {window_x_m}, "
                              f"y {window_y_m}", hint="give [low, high] with low < high")
        self.window_x_m, self.window_y_m = (x0, x1), (y0, y1)
        self.n_sigma = float(n_sigma)
        self.group_gap_leg_widths = float(group_gap_leg_widths)
        self.min_points = int(min_points)
        self.min_leg_widths = float(min_leg_widths)
        self.n_init = int(n_init)
        self.random_state = int(random_state)
        self._cache: dict = {}
        self._rng: tuple | None = None
        self._openmp = None                  # threadpoolctl's handle on OpenMP (_kmeans)

    def _xy(self, scans):
        """Cartesian points of every scan (polar → Cartesian, seed002 §II), cached per
        ScanSeries: (n_scans, n_beams) x and y, NaN for no return."""
        key = id(scans)
        hit = self._cache.get(key)
        if hit is None or hit[0] is not scans:
            a = scans.angles
            hit = (scans, scans.ranges * np.cos(a), scans.ranges * np.sin(a))
            self._cache = {key: hit}
        return hit[1], hit[2]

    def window_points(self, scans, k: int, predicted, leg_width_m: float) -> np.ndarray:
        """(M, 2) points of scan k inside the observation window, in beam order."""
        X, Y = self._xy(scans)
        base = self.window_x_m + self.window_y_m
        x0, x1, y0, y1 = window_box(predicted, leg_width_m, base, self.n_sigma)
        x, y = X[k], Y[k]
        with np.errstate(invalid="ignore"):
            keep = (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)
        return np.column_stack([x[keep], y[keep]])

    def observe(self, scans, k, predicted, leg_width_m):
        pts = self.window_points(scans, k, predicted, leg_width_m)
        groups = [g for g in split_groups(pts, self.group_gap_leg_widths * leg_width_m)
                  if len(g) >= self.min_points]                    # small groups deleted
        if not groups:
            return _NO_OBS
        P = np.concatenate(groups)
        if len(groups) == 1 and len(P) < 2 * self.min_points:
            return np.array([leg_centre(P, leg_width_m)]), ["SL"]
        labels = self._kmeans(P)                                   # K-means, k = 2
        cs = [leg_centre(P[labels == c], leg_width_m) for c in (0, 1)
              if (labels == c).sum() > 0]
        if len(cs) < 2 or math.dist(cs[0], cs[1]) < self.min_leg_widths * leg_width_m:
            return np.array([leg_centre(P, leg_width_m)]), ["SL"]  # one leg, one observation
        return np.array(cs), ["SL", "SL"]

    def _kmeans(self, P: np.ndarray) -> np.ndarray:
        import sklearn
        from sklearn.cluster import KMeans

        # Called once per frame on ~50 points, where scikit-learn's checks of its own
        # parameters and of the input cost ~17 % of the call: the parameters are fixed here
        # and P is finite (window_points keeps only points inside a finite box, no NaN).
        # Same labels (checked on the default study's rollator KF tracks).
        # One thread: scikit-learn's OpenMP threads (one per core) cost more than the
        # ~50-point fit itself when run by hand -- 4.4 against 1.0 ms a call, a rollator
        # trial's tracking 6.6 against 2.4 s wall (docs/speed.md; in the batch jobs'
        # workers no difference was measurable).  With one chunk of points the labels do
        # not depend on the thread count (the default study's rollator tracks: identical).
        if self._openmp is None:
            from threadpoolctl import ThreadpoolController

            self._openmp = ThreadpoolController().select(user_api="openmp")
        with warnings.catch_warnings(), self._openmp.limit(limits=1), sklearn.config_context(
                assume_finite=True, skip_parameter_validation=True):
            warnings.simplefilter("ignore")                       # duplicate points
            km = KMeans(n_clusters=2, n_init=self.n_init, random_state=self._seeded())
            return km.fit_predict(P)

    def _seeded(self) -> np.random.RandomState:
        """A RandomState in the state ``RandomState(random_state)`` starts in: the draws
        of an integer ``random_state``, without seeding the Mersenne twister again for
        every frame (0.1 of the ~1 ms a frame's K-means costs)."""
        if self._rng is None:
            rs = np.random.RandomState(self.random_state)
            self._rng = (rs, rs.get_state())
        else:
            self._rng[0].set_state(self._rng[1])
        return self._rng[0]
