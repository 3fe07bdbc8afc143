"""The particle filter's loops over particle–point pairs, compiled with numba (seed 002
§III.C).

Imported only when a likelihood is computed (:func:`gaitval.track.pf_likelihood.
likelihood`, lazily), so that no other job pays numba's import.  The rest of the filter
(draws, propagation, resampling, estimate) is numpy in :mod:`gaitval.track.pf`; the
likelihood visits ≈ 21,000 pairs per leg and scan, which numpy would do several times
slower.  It runs in three passes: :func:`pair_exponents` (compiled), numpy's ``np.exp``
(vectorised, the largest cost otherwise) and :func:`region_likelihood` (compiled).  The
inner loops run over the particles and are branch-free (selects, not indexing) so that the
compiler vectorises them.  ``@njit(cache=True)``: the machine code is cached beside this
file (``__pycache__``) or in ``NUMBA_CACHE_DIR``.  Same input and machine, same bits;
another CPU, numpy build or C library may round ``exp`` differently in the last digit
(docs/numerics.md).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

#: the region code of a pair outside the window's near half
OUTSIDE = 4


@njit(cache=True)
def pair_exponents(px, py, X, Y, hx, hy, mu, inv_sd):
    """Per pair (point j, particle i): the exponent −z²/2, z = (d − μ_Rm)/σ_Rm, of its
    normal density and its region 0..3 (R1..R4), −inf and :data:`OUTSIDE` when the point
    is not in the near half of the particle's window (seed002 §III.C).

    Only the points that can lie in some particle's window are kept (x in [min px − h_x,
    max px), y in [min py − h_y, max py + h_y]; NaN never).  With u = px_i − X_j,
    v = py_i − Y_j, a pair is in the near half when 0 < u ≤ h_x and |v| ≤ h_y; inner when
    |v| < u; R1/R2 (outer/inner) when v < 0 (the point on the particle's left), else R3/R4
    (inner/outer): :func:`gaitval.track.pf_model.regions`.  Returns (M, N) arrays.
    """
    near = ((X >= px.min() - hx) & (X < px.max())
            & (Y >= py.min() - hy) & (Y <= py.max() + hy))
    Xn, Yn = X[near], Y[near]
    E = np.empty((Xn.size, px.size))
    R = np.empty((Xn.size, px.size), np.int8)
    m0, m1, m2, m3 = mu[0], mu[1], mu[2], mu[3]
    s0, s1, s2, s3 = inv_sd[0], inv_sd[1], inv_sd[2], inv_sd[3]
    for j in range(Xn.size):
        for i in range(px.size):
            u, v = px[i] - Xn[j], py[i] - Yn[j]
            inside = (u > 0.0) & (u <= hx) & (abs(v) <= hy)
            inner, left = abs(v) < u, v < 0.0
            m = (m1 if inner else m0) if left else (m2 if inner else m3)
            s = (s1 if inner else s0) if left else (s2 if inner else s3)
            z = (math.sqrt(u * u + v * v) - m) * s
            E[j, i] = -0.5 * z * z if inside else -np.inf
            R[j, i] = ((1 if inner else 0) if left else (2 if inner else 3)) if inside \
                else OUTSIDE
    return E, R


@njit(cache=True)
def region_likelihood(D, R, px, py, ox, oy, model, lik, cnt):
    """p(y|x_i) = β_i · λ_i · Σ_m π_Rm · mean N(d | μ_Rm, Σ_Rm) (seed002 §III.C) into
    ``lik``, the contour points per particle into ``cnt``, from ``D = exp(E)`` and ``R``
    of :func:`pair_exponents`; ``model``: :attr:`gaitval.track.pf_likelihood.PFArrays.
    kernel`; ``ox, oy``: the other leg's estimate (β)."""
    hx, hy, mu, inv_sd, norm, pi, count_pdf, g_a, g_scale, g_lognorm = model
    N = px.size
    s0, s1, s2, s3 = np.zeros(N), np.zeros(N), np.zeros(N), np.zeros(N)
    n0, n1, n2, n3 = (np.zeros(N, np.int64), np.zeros(N, np.int64),
                      np.zeros(N, np.int64), np.zeros(N, np.int64))
    for j in range(D.shape[0]):                 # Σ densities and points per region
        for i in range(N):
            r, d = R[j, i], D[j, i]
            s0[i] += d if r == 0 else 0.0
            s1[i] += d if r == 1 else 0.0
            s2[i] += d if r == 2 else 0.0
            s3[i] += d if r == 3 else 0.0
            n0[i] += r == 0
            n1[i] += r == 1
            n2[i] += r == 2
            n3[i] += r == 3
    top = count_pdf.size - 1
    for i in range(N):
        region = (pi[0] * norm[0] * s0[i] / max(n0[i], 1)       # Σ_m π_Rm mean N(d|...)
                  + pi[1] * norm[1] * s1[i] / max(n1[i], 1)
                  + pi[2] * norm[2] * s2[i] / max(n2[i], 1)
                  + pi[3] * norm[3] * s3[i] / max(n3[i], 1))
        cnt[i] = n0[i] + n1[i] + n2[i] + n3[i]
        lam = count_pdf[min(cnt[i], top)]                        # λ_i
        d = math.hypot(px[i] - ox, py[i] - oy)                  # β_i: Gamma pdf
        beta = math.exp((g_a - 1.0) * math.log(d) - d / g_scale - g_lognorm) if d > 0 else 0.0
        lik[i] = beta * lam * region                            # seed002 §III.C
