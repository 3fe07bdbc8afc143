"""The particle filter's model arrays, draws and likelihood (seed 002 §III).

:class:`PFArrays` turns a model (:mod:`gaitval.track.pf_model`) into the arrays the
per-scan steps use (and the tuple the compiled likelihood of :mod:`gaitval.track.pf_kernels`
takes); :func:`sample_velocities` draws from the Gaussian mixtures (§III.A–B);
:func:`likelihood` weighs one leg's particles against the scan's points near them
(§III.C, the compiled kernel).  numba is imported only when a likelihood is computed.

Notes
-----
seed002 §III.C: p(y|x_i) = β_i · [λ_i · Σ_{m=1..4} π_Rm · N(d_Rm | μ_Rm, Σ_Rm)]; the
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

from gaitval.track.pf_model import SIDES, check_model


class PFArrays:
    """The model as arrays (per leg, component, region) for the vectorised steps.

    Attributes
    ----------
    w : (2, 2) mixture weights per leg; mean : (2, 2, 2); chol : (2, 2, 2, 2) Cholesky
    factors of the covariances; hx, hy : window half-sizes; mu, inv_sd, norm, pi : (4,)
    per region R1..R4; count_pdf : (T,); gamma_a, gamma_scale, gamma_lognorm : β's
    constants; walk_sd : (2,) m/s; kernel : the tuple (hx, hy, mu, inv_sd, norm, pi,
    count_pdf, gamma_a, gamma_scale, gamma_lognorm) that
    :func:`gaitval.track.pf_kernels.region_likelihood` takes.
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
        from scipy.special import gammaln   # here: importing gaitval.track need not load it

        self.gamma_lognorm = gammaln(self.gamma_a) + self.gamma_a * math.log(self.gamma_scale)
        self.walk_sd = np.asarray(model["walk_sd_mps"], dtype=float)
        c = np.ascontiguousarray
        self.kernel = (self.hx, self.hy, c(self.mu), c(self.inv_sd), c(self.norm),
                       c(self.pi), c(self.count_pdf), self.gamma_a, self.gamma_scale,
                       float(self.gamma_lognorm))


def sample_velocities(P: PFArrays, rng: np.random.Generator, n: int,
                      zero_mean: bool = False) -> np.ndarray:
    """(2, n, 2) velocities drawn from each leg's 2-component mixture (seed002 §III.B);
    ``zero_mean``: the same mixture centred on zero (§III.A)."""
    u, z = draw_mixture(rng, n)
    second = u >= P.w[:, None, :1]                                   # component per draw
    L, m = P.chol, P.mean                                            # (2, 2, 2, 2), (2, 2, 2)
    # v = m_c + L_c z with L_c lower triangular (c = the draw's component)
    vx = z[..., :1] * np.where(second, L[:, None, 1:, 0, 0], L[:, None, :1, 0, 0])
    vy = (z[..., :1] * np.where(second, L[:, None, 1:, 1, 0], L[:, None, :1, 1, 0])
          + z[..., 1:] * np.where(second, L[:, None, 1:, 1, 1], L[:, None, :1, 1, 1]))
    v = np.concatenate([vx, vy], axis=2)
    if not zero_mean:
        v += np.where(second, m[:, None, 1], m[:, None, 0])
    return v


def draw_mixture(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The draws of :func:`sample_velocities`, in its order: (2, n, 1) uniforms (the
    component) and (2, n, 2) standard normals."""
    return rng.random((2, n, 1)), rng.standard_normal((2, n, 2))


def likelihood(P: PFArrays, px: np.ndarray, py: np.ndarray, X: np.ndarray, Y: np.ndarray,
               ox: float, oy: float) -> tuple[np.ndarray, np.ndarray]:
    """Observation likelihood of one leg's K particles against a scan's points (seed002
    §III.C), by the compiled loops of :mod:`gaitval.track.pf_kernels`.

    Parameters
    ----------
    P : PFArrays
    px, py : (K,) particle positions, sensor frame.
    X, Y : (M,) the scan's points (NaN: no return).
    ox, oy : float, the other leg's estimate (for β).

    Returns
    -------
    weights : (K,) unnormalised p(y|x) (module notes)
    counts : (K,) contour points (points in R1..R4 of the particle's window)

    Notes
    -----
    Per pair, with u = x_particle − x_point (> 0: the point is in the lower half) and
    v = y_particle − y_point: in the window when 0 < u ≤ h_x and |v| ≤ h_y; inner when
    |v| < u; the region R1..R4 as :func:`gaitval.track.pf_model.regions`.  Only the points
    that can lie in some particle's window are visited (x in [min px − h_x, max px),
    y in [min py − h_y, max py + h_y]).
    """
    from gaitval.track.pf_kernels import pair_exponents, region_likelihood

    px, py = np.ascontiguousarray(px, dtype=float), np.ascontiguousarray(py, dtype=float)
    E, R = pair_exponents(px, py, np.ascontiguousarray(X, dtype=float),
                          np.ascontiguousarray(Y, dtype=float), P.hx, P.hy, P.mu, P.inv_sd)
    np.exp(E, out=E)                            # N(d | μ, σ) up to the factor 1/(σ√2π)
    lik, cnt = np.empty(px.size), np.empty(px.size, dtype=np.intp)
    region_likelihood(E, R, px, py, float(ox), float(oy), P.kernel, lik, cnt)
    return lik, cnt
