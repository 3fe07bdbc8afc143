"""The particle filter's learned parameters (seed 002 §III), and how they are learned.

Seed 002 §III says the PF's parameters "have been experimentally defined" and gives none of
them.  gaitval learns each one from ground truth and laser scans of *other subjects*
(leave-one-subject-out: the workflow trains one model per held-out subject, never on the
tested trial), with these rules:

=================  =====================================================================
parameter          learned as
=================  =====================================================================
GMM per leg        scikit-learn ``GaussianMixture(2, covariance_type="full")`` on the true
(§III.B)           leg velocities (vx, vy) relative to the laser, per leg (L, R).
init velocities    the same mixture with its means set to zero (§III.A "zero-mean GMM":
(§III.A)           both legs still in front of the rollator).
window (§III.C)    half-sizes (h_x, h_y) of the rectangle around a particle: the 99th
                   percentile of |Δx| and |Δy| between a true leg centre and the laser
                   points on that leg (points within one leg width of the centre and
                   nearer to it than to the other leg's centre).
μ_Rm, σ_Rm         mean and standard deviation of the distances to the true centre of all
(§III.C.1)         points in the window, lower semicircle, region R1..R4.
π_Rm               each region's share of those points: a circle seen by a laser returns
                   more points where its surface faces the laser, so the inner regions
                   R2, R3 outweigh R1, R4, as §III.C requires (π_1, π_4 < π_2, π_3).
λ (§III.C.2)       "normal kernel distribution" of the number of contour points (points in
                   the window, lower semicircle) at the true centre: a Gaussian kernel
                   density (``scipy.stats.gaussian_kde``), stored as a table over counts.
β (§III.C.3)       ``scipy.stats.gamma.fit(d, floc=0)`` of the true distance between the legs.
random walk (D)    per-axis standard deviation of the change of the true leg velocity from
                   one scan to the next (the walk moves velocities; positions follow).
=================  =====================================================================

Regions: the circle around a particle is divided by the line through it perpendicular to
the laser's forward axis (x); the far half R0 is ignored; the near half (points with
Δx < 0) is split into four 45° sectors, ordered from the laser's left: R1 (outer, Δy > 0),
R2 (inner, Δy > 0), R3 (inner, Δy ≤ 0), R4 (outer, Δy ≤ 0); inner means |Δy| < −Δx.

When a study has no other subject (the tiny test study), :func:`default_pf_model` gives
geometric placeholders instead, and the model says so (``source``).

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017, §III.
"""
from __future__ import annotations

import math

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, GaitvalError

MODEL_VERSION = 1
#: the sides of the ground-truth table, in filter order
SIDES = ("L", "R")
#: points farther than this from a true centre are never kept for training (m)
_NEAR_M = 0.25


def regions(dx: np.ndarray, dy: np.ndarray) -> np.ndarray:
    """Region index 0..3 (R1..R4) of offsets (point − centre), −1 in R0 (module notes)."""
    inner = np.abs(dy) < -dx
    r = np.where(dy > 0, np.where(inner, 1, 0), np.where(inner, 2, 3))
    return np.where(dx < 0, r, -1)


# -- training samples of one trial --------------------------------------------------------
def training_samples(scans, gt: pd.DataFrame, leg_width_m: float) -> dict:
    """What one training trial contributes: true velocities, inter-leg distances, velocity
    changes and the laser points near each true centre.

    Parameters
    ----------
    scans : ScanSeries
        The trial's laser scans.
    gt : DataFrame
        Its ground truth (:data:`gaitval.groundtruth.GT_COLUMNS`: ``scan, side, xs_m, ys_m,
        vxs_mps, vys_mps, valid``), sensor frame.
    leg_width_m : float
        The subject's leg width (for attributing points to a leg).

    Returns
    -------
    dict of arrays: ``vel_L``, ``vel_R`` (n, 2); ``dist`` (n,); ``dvel`` (n, 2);
    ``offsets`` (m, 2) point − centre; ``frame`` (m,) int (a frame × leg id unique within
    the trial); ``own`` (m,) bool (the point is attributed to that leg); ``n_frames`` int.
    """
    g = {s: gt[gt["side"] == s].set_index("scan").reindex(range(scans.n_scans)) for s in SIDES}
    C = np.stack([g[s][["xs_m", "ys_m"]].to_numpy(float) for s in SIDES], axis=1)  # (n,2,2)
    V = np.stack([g[s][["vxs_mps", "vys_mps"]].to_numpy(float) for s in SIDES], axis=1)
    ok = np.ones(scans.n_scans, bool)
    for s in SIDES:
        ok &= g[s]["valid"].fillna(False).to_numpy(bool)
    ok &= np.isfinite(C).all(axis=(1, 2)) & np.isfinite(V).all(axis=(1, 2))
    dv = np.diff(V, axis=0)
    dv_ok = ok[1:] & ok[:-1]
    a = scans.angles
    X, Y = scans.ranges * np.cos(a), scans.ranges * np.sin(a)
    offs, frame, own = [], [], []
    for k in np.flatnonzero(ok):
        P = np.column_stack([X[k], Y[k]])
        P = P[np.isfinite(P[:, 0])]
        d = np.linalg.norm(P[:, None, :] - C[k][None], axis=2)          # (M, 2)
        for f in (0, 1):
            near = d[:, f] < _NEAR_M
            offs.append(P[near] - C[k, f])
            frame.append(np.full(int(near.sum()), 2 * k + f))
            own.append((d[near, f] < leg_width_m) & (d[near, f] <= d[near, 1 - f]))
    cat = (lambda xs, shape: np.concatenate(xs) if xs else np.zeros(shape))
    return {"vel_L": V[ok, 0], "vel_R": V[ok, 1],
            "dist": np.linalg.norm(C[ok, 0] - C[ok, 1], axis=1),
            "dvel": dv[dv_ok].reshape(-1, 2),
            "offsets": cat(offs, (0, 2)), "frame": cat(frame, (0,)).astype(np.int64),
            "own": cat(own, (0,)).astype(bool), "n_frames": int(ok.sum())}


# -- the model ------------------------------------------------------------------------------
def _gmm_dict(gm) -> dict:
    return {"weights": gm.weights_.tolist(), "means": gm.means_.tolist(),
            "covariances": gm.covariances_.tolist()}


def _fit_gmm(v: np.ndarray, seed: int):
    from sklearn.mixture import GaussianMixture

    if len(v) < 10:
        raise GaitvalError(f"too few ground-truth velocities ({len(v)}) to train the PF's "
                           "velocity mixture (seed 002 §III.B)")
    return GaussianMixture(n_components=2, covariance_type="full",
                           random_state=seed).fit(v)                   # seed002 §III.B


def _count_table(counts: np.ndarray) -> list[float]:
    """λ: Gaussian KDE of the contour-point counts, evaluated at 0..max+50 (seed002 §III.C.2)."""
    from scipy.stats import gaussian_kde

    counts = np.asarray(counts, dtype=float)
    grid = np.arange(int(counts.max()) + 51)
    if np.ptp(counts) == 0:                          # degenerate: a single count value
        return (np.exp(-0.5 * (grid - counts[0]) ** 2) / math.sqrt(2 * math.pi)).tolist()
    return gaussian_kde(counts)(grid).tolist()


def train_pf_model(samples: list[dict], *, seed: int = 0, trained_on=(), held_out="",
                   window_quantile: float = 0.99) -> dict:
    """Learn the PF's parameters from the training trials' samples (module notes).

    Parameters
    ----------
    samples : list of dict
        :func:`training_samples` of every training trial (other subjects only).
    seed : int
        ``random_state`` of the Gaussian mixtures.
    trained_on : sequence of str
        Training trial ids (recorded in the model).
    held_out : str
        The subject the model is for (recorded).
    window_quantile : float
        Quantile of the point offsets that sets the window half-sizes.

    Returns
    -------
    dict
        JSON-ready model (see :func:`default_pf_model` for the keys).
    """
    from scipy.stats import gamma

    if not samples or sum(s["n_frames"] for s in samples) == 0:
        raise GaitvalError("no training frames for the PF model (every training trial "
                           "lacks valid ground truth)")
    cat = {k: np.concatenate([s[k] for s in samples]) for k in
           ("vel_L", "vel_R", "dist", "dvel", "offsets", "own")}
    frame = np.concatenate([s["frame"] + 10 ** 7 * i for i, s in enumerate(samples)])
    O = cat["offsets"]
    hx, hy = np.quantile(np.abs(O[cat["own"]]), window_quantile, axis=0)     # §III.C window
    inwin = (np.abs(O[:, 0]) <= hx) & (np.abs(O[:, 1]) <= hy)
    reg = regions(O[:, 0], O[:, 1])
    use = inwin & (reg >= 0)
    d = np.hypot(O[use, 0], O[use, 1])
    r = reg[use]
    n_r = np.bincount(r, minlength=4)
    if (n_r < 2).any():
        raise GaitvalError(f"too few training points per region R1..R4 ({n_r.tolist()}) for "
                           "the PF's distance distributions (seed 002 §III.C.1)")
    mu = [float(d[r == m].mean()) for m in range(4)]                 # μ_Rm
    sd = [float(d[r == m].std(ddof=1)) for m in range(4)]            # Σ_Rm (1-D)
    # contour-point counts per (frame, leg), zero where a leg had none (§III.C.2)
    seen = np.unique(frame[use], return_counts=True)[1]
    n_units = sum(2 * s["n_frames"] for s in samples)
    counts = np.concatenate([seen, np.zeros(max(n_units - len(seen), 0))])
    a, _, scale = gamma.fit(cat["dist"], floc=0.0)                    # β, §III.C.3
    return {
        "version": MODEL_VERSION, "source": "leave-one-subject-out",
        "held_out_subject": str(held_out), "trained_on": sorted(map(str, trained_on)),
        "n_frames": int(sum(s["n_frames"] for s in samples)), "seed": int(seed),
        "gmm": {s: _gmm_dict(_fit_gmm(cat[f"vel_{s}"], seed)) for s in SIDES},
        "window_half_m": [float(hx), float(hy)],
        "regions": {"mu_m": mu, "sd_m": sd, "pi": (n_r / n_r.sum()).tolist()},
        "count_pdf": _count_table(counts),
        "gamma": {"a": float(a), "scale": float(scale)},
        "walk_sd_mps": np.std(cat["dvel"], axis=0, ddof=1).tolist(),
    }


def default_pf_model(leg_width_m: float = 0.10) -> dict:
    """Geometric placeholders for a study without other subjects (module notes).

    A leg is a circle of radius ρ = w_l/2: window ±w_l; distances N(ρ, ρ/3); region shares
    of a circle sampled evenly across its width, (1 − sin 45°)/2 outer and sin 45°/2 inner;
    λ flat (no count information); β a Gamma with mean 2 w_l and sd 0.8 w_l; velocities a
    still and a swinging component (sd 0.1 and 0.6 / 0.2 m/s along x / y); walk 0.2 m/s.
    """
    w = float(leg_width_m)
    rho = 0.5 * w
    inner, outer = math.sin(math.pi / 4) / 2, (1 - math.sin(math.pi / 4)) / 2
    mean, sdv = 2.0 * w, 0.8 * w
    cov = [[[0.01, 0.0], [0.0, 0.01]], [[0.36, 0.0], [0.0, 0.04]]]
    gmm = {"weights": [0.6, 0.4], "means": [[0.0, 0.0], [0.0, 0.0]], "covariances": cov}
    return {
        "version": MODEL_VERSION, "source": "defaults (no other subject to learn from)",
        "held_out_subject": "", "trained_on": [], "n_frames": 0, "seed": 0,
        "gmm": {"L": gmm, "R": gmm}, "window_half_m": [w, w],
        "regions": {"mu_m": [rho] * 4, "sd_m": [rho / 3] * 4,
                    "pi": [outer, inner, inner, outer]},
        "count_pdf": [1.0] * 400,
        "gamma": {"a": (mean / sdv) ** 2, "scale": sdv ** 2 / mean},
        "walk_sd_mps": [0.2, 0.2],
    }


def check_model(model: dict, where: str = "PF model") -> dict:
    """The model's keys and shapes, or a ConfigError naming what is wrong."""
    need = ("gmm", "window_half_m", "regions", "count_pdf", "gamma", "walk_sd_mps")
    miss = [k for k in need if k not in model]
    if miss or model.get("version") != MODEL_VERSION:
        raise ConfigError(f"{where}: not a gaitval PF model (missing {miss}, version "
                          f"{model.get('version')!r}, expected {MODEL_VERSION})",
                          hint="train it with `gaitval rollator-train`")
    for s in SIDES:
        g = model["gmm"][s]
        if np.shape(g["means"]) != (2, 2) or np.shape(g["covariances"]) != (2, 2, 2):
            raise ConfigError(f"{where}: gmm.{s} must have 2 components in 2-D")
    return model
