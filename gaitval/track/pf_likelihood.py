"""The particle filter's arithmetic, vectorised over both legs' particles (seed 002 §III).

:class:`PFArrays` turns a model (:mod:`gaitval.track.pf_model`) into the arrays the
per-scan steps use; :func:`sample_velocities` draws from the Gaussian mixtures (§III.A–B);
:func:`likelihood` weighs every particle of both legs against one scan in one pass
(§III.C); :func:`effective_size` and :func:`systematic_resample` serve §III.D.

Notes
-----
seed002 §III.C: p(y|x_i) = β_i · [λ_i · Σ_{m=1..4} π_Rm · N(d_Rm | μ_Rm, Σ_Rm)], where the
points y are those inside the rectangle (±h_x, ±h_y) centred on particle i, R0 (the half
farther from the laser) is ignored, d_Rm are the distances of the points of region R_m to
the particle, λ_i is the count kernel at the number of points in R1..R4, and β_i the Gamma
density of the distance between particle i and the other leg.  A region holding several
points contributes the *mean* of their normal densities (gaitval's reading of
"N(d_Rm | μ_Rm, Σ_Rm)" for a vector of distances: each point counts equally, an outlier
adds almost nothing and lowers the mean), a region without points contributes 0.  β is
evaluated against the other leg's estimate at k−1, so the two filters are updated in the
same way whichever goes first.
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import gammaln

from gaitval.track.pf_model import SIDES, check_model


class PFArrays:
    """The model as arrays (per leg, component, region) for the vectorised steps.

    Attributes
    ----------
    w : (2, 2) mixture weights per leg; mean : (2, 2, 2); chol : (2, 2, 2, 2) Cholesky
    factors of the covariances; hx, hy : window half-sizes; mu, inv_sd, norm, pi : (4,)
    per region; count_pdf : (T,); gamma_a, gamma_scale, gamma_lognorm : β's constants;
    walk_sd : (2,) m/s.
    """

    def __init__(self, model: dict):
        check_model(model)
        g = [model["gmm"][s] for s in SIDES]
        self.w = np.array([x["weights"] for x in g], dtype=float)
        self.w /= self.w.sum(axis=1, keepdims=True)
        self.mean = np.array([x["means"] for x in g], dtype=float)
        self.chol = np.linalg.cholesky(np.array([x["covariances"] for x in g], dtype=float))
        self.hx, self.hy = (float(v) for v in model["window_half_m"])
        reg = model["regions"]
        sd = np.asarray(reg["sd_m"], dtype=float)
        self.mu = np.asarray(reg["mu_m"], dtype=float)
        self.inv_sd = 1.0 / sd
        self.norm = 1.0 / (sd * math.sqrt(2.0 * math.pi))
        self.pi = np.asarray(reg["pi"], dtype=float)
        self.count_pdf = np.asarray(model["count_pdf"], dtype=float)
        ga = model["gamma"]
        self.gamma_a, self.gamma_scale = float(ga["a"]), float(ga["scale"])
        self.gamma_lognorm = gammaln(self.gamma_a) + self.gamma_a * math.log(self.gamma_scale)
        self.walk_sd = np.asarray(model["walk_sd_mps"], dtype=float)


def sample_velocities(P: PFArrays, rng: np.random.Generator, n: int,
                      zero_mean: bool = False) -> np.ndarray:
    """(2, n, 2) velocities drawn from each leg's 2-component mixture (seed002 §III.B);
    ``zero_mean``: the same mixture centred on zero (§III.A)."""
    second = rng.random((2, n, 1)) >= P.w[:, None, :1]               # component per draw
    z = rng.standard_normal((2, n, 2))
    L, m = P.chol, P.mean                                            # (2, 2, 2, 2), (2, 2, 2)
    # v = m_c + L_c z with L_c lower triangular (c = the draw's component)
    vx = z[..., :1] * np.where(second, L[:, None, 1:, 0, 0], L[:, None, :1, 0, 0])
    vy = (z[..., :1] * np.where(second, L[:, None, 1:, 1, 0], L[:, None, :1, 1, 0])
          + z[..., 1:] * np.where(second, L[:, None, 1:, 1, 1], L[:, None, :1, 1, 1]))
    v = np.concatenate([vx, vy], axis=2)
    if not zero_mean:
        v += np.where(second, m[:, None, 1], m[:, None, 0])
    return v


def gamma_pdf(P: PFArrays, d: np.ndarray) -> np.ndarray:
    """β: Gamma(a, scale) density at d (= ``scipy.stats.gamma(a, scale=s).pdf``)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        lp = (P.gamma_a - 1.0) * np.log(d) - d / P.gamma_scale - P.gamma_lognorm
    return np.where(d > 0, np.exp(lp), 0.0)


def likelihood(P: PFArrays, px: np.ndarray, py: np.ndarray, X: np.ndarray, Y: np.ndarray,
               ox: np.ndarray, oy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Observation likelihood of K particles against one scan's points (module notes).

    Parameters
    ----------
    P : PFArrays
    px, py : (K,) particle positions (both legs stacked), sensor frame.
    X, Y : (M,) the scan's points near the particles.
    ox, oy : (K,) the other leg's estimate for each particle (for β).

    Returns
    -------
    weights : (K,) unnormalised p(y|x) (seed002 §III.C)
    counts : (K,) contour points (points in R1..R4 of the particle's window)
    """
    K = len(px)
    dx = X[None, :] - px[:, None]
    dy = Y[None, :] - py[:, None]
    inwin = (dx < 0.0) & (dx >= -P.hx) & (np.abs(dy) <= P.hy)        # window ∩ lower half
    row, col = np.nonzero(inwin)
    dxm, dym = dx[row, col], dy[row, col]
    inner = (np.abs(dym) < -dxm).astype(np.intp)
    r = np.where(dym > 0.0, inner, 3 - inner)                          # R1..R4 → 0..3
    z = (np.sqrt(dxm * dxm + dym * dym) - P.mu[r]) * P.inv_sd[r]
    dens = np.exp(-0.5 * z * z) * P.norm[r]                           # N(d | μ_Rm, Σ_Rm)
    key = row * 4 + r
    sums = np.bincount(key, weights=dens, minlength=4 * K).reshape(K, 4)
    cnts = np.bincount(key, minlength=4 * K).reshape(K, 4)
    region_term = (sums / np.maximum(cnts, 1)) @ P.pi                 # Σ_m π_Rm · N(...)
    n = cnts.sum(axis=1)
    lam = P.count_pdf[np.minimum(n, len(P.count_pdf) - 1)]            # λ_i
    beta = gamma_pdf(P, np.hypot(px - ox, py - oy))                    # β_i
    return beta * lam * region_term, n                                # seed002 §III.C


def effective_size(w: np.ndarray) -> np.ndarray:
    """N_eff = 1 / Σ ω̂² per row of normalised weights (seed002 §III.D)."""
    return 1.0 / np.sum(w * w, axis=-1)


def systematic_resample(w: np.ndarray, u: np.ndarray) -> np.ndarray:
    """Indices (rows × N) drawn by systematic resampling of normalised weights ``w`` (rows,
    N), with one uniform ``u`` per row (Arulampalam et al. 2002, Algorithm 2)."""
    n = w.shape[-1]
    c = np.cumsum(w, axis=-1)
    c[..., -1] = 1.0
    pos = (np.arange(n)[None, :] + u[:, None]) / n
    return np.stack([np.searchsorted(c[i], pos[i]) for i in range(len(w))])
