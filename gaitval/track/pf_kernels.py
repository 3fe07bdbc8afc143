"""The particle filter's per-scan arithmetic, compiled with numba (seed 002 §III.B–E).

Imported only by the PF (lazily, from :mod:`gaitval.track.pf` and
:func:`gaitval.track.pf_likelihood.likelihood`), so that no other job pays numba's import.
Every kernel is ``@njit(cache=True)`` without ``fastmath``: IEEE arithmetic, no
reassociation and no contraction into fused multiply-adds (the only ones are the explicit
``llvm.fma`` of ``libc_exp``), and the compiled machine code is cached beside this
file (``__pycache__``, or ``NUMBA_CACHE_DIR``), so a process pays numba's import and the
loading of the cached kernels once, not a compilation (docs/rollator.md, "Speed").

Same numbers as the vectorised numpy version these kernels replace (gaitval ≤ ddd5125),
bit for bit:

* random draws are not made here: :mod:`gaitval.track.pf` draws them with the
  ``numpy.random.Generator`` in the same order and shapes as before and passes them in;
* ``log``, ``sqrt`` and ``hypot`` are the C library's, as numpy's are for float64 on x86-64
  without AVX-512 (numpy's AVX-512 ``exp``/``log`` may differ in the last bit); ``exp`` is
  the C library's algorithm inlined (:func:`gaitval.track.pf_exp.libc_exp`, bit-equal to
  glibc's x86-64 ``exp``; other C libraries may round a last bit differently, and so would
  numpy there), vectorised over the particles in the region sums;
* sums keep numpy's order: each region sum adds its pairs point ascending (the order of
  ``np.bincount``'s particle-major pass, here point-major for all particles at once); row
  sums are numpy's pairwise summation (:func:`pairwise_sum`); the weighted means add
  sequentially from 0 (``np.einsum``); the four-region dot product is (R1 + R4) + (R2 + R3)
  in pair-code order 0, 2, 1, 3 — the order OpenBLAS's x86-64 ``dgemv`` used for
  ``means @ pi`` (a fixed order here, on every machine).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from gaitval.track.pf_exp import (_C2, _C3, _C4, _C5, _EXP_TAB, _INVLN2N, _NEGLN2HIN,
                                  _NEGLN2LON, _SHIFT, _bits, _double, _fma, libc_exp)

#: numpy's block size of pairwise summation (numpy/_core/src/umath/loops_utils.h.src)
_PW_BLOCK = 128


@njit(cache=True)
def _block_sum(a, lo, n):
    """numpy's pairwise summation of ≤ 128 values: 8 running sums, then the rest."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r = np.empty(8)
    for j in range(8):
        r[j] = a[lo + j]
    i = 8
    while i < n - n % 8:
        for j in range(8):
            r[j] += a[lo + i + j]
        i += 8
    res = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@njit(cache=True)
def pairwise_sum(a, lo, n):
    """Sum of ``a[lo:lo + n]`` in numpy's pairwise order (``np.sum`` of a float64 row is
    ``0.0 + pairwise_sum``): blocks of > 128 split at n2 = n/2 rounded down to a multiple of
    8, sum(left) + sum(right).  Iterative (an explicit stack): numba cannot load a cached
    recursive function."""
    t_lo, t_n = np.empty(2 * 64, np.intp), np.empty(2 * 64, np.intp)   # tasks; n −1: add
    vals = np.empty(64)
    nt, nv = 1, 0
    t_lo[0], t_n[0] = lo, n
    while nt:
        nt -= 1
        lo_, n_ = t_lo[nt], t_n[nt]
        if n_ < 0:                                    # both halves done: left + right
            nv -= 1
            vals[nv - 1] = vals[nv - 1] + vals[nv]
        elif n_ <= _PW_BLOCK:
            vals[nv] = _block_sum(a, lo_, n_)
            nv += 1
        else:
            n2 = n_ // 2
            n2 -= n2 % 8
            t_lo[nt], t_n[nt] = 0, -1                 # then add, after
            t_lo[nt + 1], t_n[nt + 1] = lo_ + n2, n_ - n2   # the right half, after
            t_lo[nt + 2], t_n[nt + 2] = lo_, n2       # the left half, first
            nt += 3
    return vals[0]


@njit(cache=True)
def near_points(X, Y, px, py, hx, hy):
    """Indices of the points that can be in the lower half-window of some particle:
    x in [min px − h_x, max px), y in [min py − h_y, max py + h_y] (scan order)."""
    x0, x1, y0, y1 = px.min() - hx, px.max(), py.min() - hy, py.max() + hy
    keep = np.empty(X.size, np.intp)
    m = 0
    for j in range(X.size):
        if X[j] >= x0 and X[j] < x1 and Y[j] >= y0 and Y[j] <= y1:   # NaN: never kept
            keep[m] = j
            m += 1
    return keep[:m]


@njit(cache=True, inline="always")
def _pair_exponent(pxi, pyi, xj, yj, hx, hy, A, B, C):
    """Pair (particle, point): the pair code (4: outside the window's near half) and the
    exponent of the pair's normal density (−1 outside); ``A, B, C``: the coefficients
    per code (``abc``'s columns, as 4-tuples).  Branch-free (vectorises)."""
    u = pxi - xj
    v = pyi - yj
    av = abs(v)
    inside = (u > 0.0) & (u <= hx) & (av <= hy)                     # window ∩ lower half
    inner, left = av < u, v >= 0.0                                    # seed002 §III.C R_m
    a = (A[3] if inner else A[2]) if left else (A[1] if inner else A[0])
    b = (B[3] if inner else B[2]) if left else (B[1] if inner else B[0])
    c = (C[3] if inner else C[2]) if left else (C[1] if inner else C[0])
    d2 = u * u + v * v
    x = a * d2 + b * math.sqrt(d2) + c                                # ln N(d | μ_Rm, Σ_Rm)
    return ((inner + 2 * left) if inside else 4), (x if inside else -1.0)


@njit(cache=True, inline="always")
def _columns(abc):
    """``abc``'s three columns as 4-tuples of scalars."""
    return ((abc[0, 0], abc[1, 0], abc[2, 0], abc[3, 0]),
            (abc[0, 1], abc[1, 1], abc[2, 1], abc[3, 1]),
            (abc[0, 2], abc[1, 2], abc[2, 2], abc[3, 2]))


@njit(cache=True)
def _region_sums(px, py, X, Y, near, hx, hy, abc, s, n):
    """Σ of the pair densities (``s``, (4, N)) and pair counts (``n``) per particle and
    code, the points ``near`` ascending: the point loop outer, the particle loop inner (it
    vectorises, :func:`libc_exp`'s formula with its table look-ups inlined).  Returns False
    (sums unusable) when an exponent lies outside the formula's range 2^-54 ≤ |x| < 512."""
    tab = _EXP_TAB
    A, B, C = _columns(abc)
    s0, s1, s2, s3 = s[0], s[1], s[2], s[3]
    n0, n1, n2, n3 = n[0], n[1], n[2], n[3]
    ok = True
    for j in near:                                                    # point ascending
        xj, yj = X[j], Y[j]
        for i in range(px.size):
            c, x = _pair_exponent(px[i], py[i], xj, yj, hx, hy, A, B, C)
            ax = abs(x)
            ok &= (ax < 512.0) & (ax >= 5.551115123125783e-17)
            kd = _INVLN2N * x + _SHIFT                                # libc_exp, inlined
            ki = _bits(kd)
            kd -= _SHIFT
            r = _fma(kd, _NEGLN2LON, _fma(kd, _NEGLN2HIN, x))
            t = (ki & np.uint64(127)) << np.uint64(1)
            scale = _double(tab[t + np.uint64(1)] + (ki << np.uint64(45)))
            rr = r * r
            tmp = _fma(rr * rr, _fma(r, _C5, _C4), _fma(rr, _fma(r, _C3, _C2),
                                                         _double(tab[t]) + r))
            dens = _fma(scale, tmp, scale)                            # N(d | μ_Rm, Σ_Rm)
            s0[i] += dens if c == 0 else 0.0
            s1[i] += dens if c == 1 else 0.0
            s2[i] += dens if c == 2 else 0.0
            s3[i] += dens if c == 3 else 0.0
            n0[i] += c == 0
            n1[i] += c == 1
            n2[i] += c == 2
            n3[i] += c == 3
    return ok


@njit(cache=True)
def _region_sums_exact(px, py, X, Y, near, hx, hy, abc, s, n):
    """:func:`_region_sums` pair by pair with :func:`libc_exp` (the library's ``exp``
    outside the formula's range): same order, any exponent."""
    A, B, C = _columns(abc)
    for j in near:
        for i in range(px.size):
            c, x = _pair_exponent(px[i], py[i], X[j], Y[j], hx, hy, A, B, C)
            if c < 4:
                s[c, i] += libc_exp(x)
                n[c, i] += 1


@njit(cache=True)
def leg_likelihood(px, py, X, Y, ox, oy, model, lik, cnt):
    """Unnormalised p(y|x) of one leg's particles into ``lik``, contour counts into ``cnt``
    (seed002 §III.C; formula in :func:`gaitval.track.pf_likelihood.likelihood`).

    ``model``: :attr:`gaitval.track.pf_likelihood.PFArrays.kernel`.  A pair (particle i,
    point j) with u = px_i − X_j, v = py_i − Y_j is in the window's near half when
    0 < u ≤ h_x and |v| ≤ h_y; its pair code is [|v| < u] + 2·[v ≥ 0] (R1, R2, R4, R3).
    Each region's densities are added point ascending from 0, one running sum per particle
    and region; the loop over the points is the outer one and the particles are the inner,
    vectorised one, so every sum adds the same terms in the same order as a particle-major
    loop (numpy's ``np.bincount``).  A pair outside the window or in another region adds
    nothing (as adding +0.0 to a sum ≥ +0: the same number).
    """
    _, _, _, hx, hy, abc, pi, count_pdf, g_a, g_scale, g_lognorm, _ = model
    near = near_points(X, Y, px, py, hx, hy)
    N = px.size
    s, cn = np.zeros((4, N)), np.zeros((4, N), np.int64)            # Σ dens, points per code
    if not _region_sums(px, py, X, Y, near, hx, hy, abc, s, cn):
        s[:], cn[:] = 0.0, 0                                          # rare: pair by pair
        _region_sums_exact(px, py, X, Y, near, hx, hy, abc, s, cn)
    top = count_pdf.size - 1
    for i in range(N):
        m0, m1 = s[0, i] / max(cn[0, i], 1.0), s[1, i] / max(cn[1, i], 1.0)   # mean per
        m2, m3 = s[2, i] / max(cn[2, i], 1.0), s[3, i] / max(cn[3, i], 1.0)   # region
        region = (m0 * pi[0] + m2 * pi[2]) + (m1 * pi[1] + m3 * pi[3])   # Σ_m π_Rm N(...)
        n = cn[0, i] + cn[1, i] + cn[2, i] + cn[3, i]
        lam = count_pdf[min(n, top)]                                  # λ_i
        d = math.hypot(px[i] - ox, py[i] - oy)
        beta = 0.0                                                    # β_i: Gamma pdf
        if d > 0.0:
            beta = libc_exp((g_a - 1.0) * math.log(d) - d / g_scale - g_lognorm)
        lik[i] = beta * lam * region                                  # seed002 §III.C
        cnt[i] = n


@njit(cache=True)
def normalise(lik, w):
    """Weights ``w`` = ``lik`` / Σ lik; all zero (no information): uniform.  Returns
    N_eff = 1 / Σ ω̂² (seed002 §III.D)."""
    N = lik.size
    s = 0.0 + pairwise_sum(lik, 0, N)
    for n in range(N):
        w[n] = lik[n] / s if s > 0.0 else 1.0 / N
    sq = w * w
    return 1.0 / (0.0 + pairwise_sum(sq, 0, N))


@njit(cache=True)
def propagate_weigh(prev, dt, u, z, X, Y, model, resample_fraction):
    """§III.B–C for both legs from the draws ``u`` (2, N, 1) uniform and ``z`` (2, N, 2)
    standard normal.

    Returns the particles' velocities ``vx, vy`` and positions ``px, py`` (2, N), their
    likelihoods and normalised weights (2, N), ``seen`` (2,): some particle had contour
    points, and ``need`` (2,): N_eff < resample_fraction · N (§III.D)."""
    w_mix, chol, mean = model[0], model[1], model[2]
    N = u.shape[1]
    vx, vy = np.empty((2, N)), np.empty((2, N))
    px, py = np.empty((2, N)), np.empty((2, N))
    lik, w = np.empty((2, N)), np.empty((2, N))
    cnt = np.empty(N, np.intp)
    seen, need = np.zeros(2, np.bool_), np.zeros(2, np.bool_)
    for f in range(2):
        for n in range(N):
            k = 1 if u[f, n, 0] >= w_mix[f, 0] else 0                 # mixture component
            L = chol[f, k]                                            # v = m_k + L_k z
            vx[f, n] = z[f, n, 0] * L[0, 0] + mean[f, k, 0]           # seed002 §III.B
            vy[f, n] = (z[f, n, 0] * L[1, 0] + z[f, n, 1] * L[1, 1]) + mean[f, k, 1]
            px[f, n] = prev[f, 0] + vx[f, n] * dt                     # p = p̂_{k−1} + v Δt
            py[f, n] = prev[f, 1] + vy[f, n] * dt
    for f in range(2):                                                # seed002 §III.C
        leg_likelihood(px[f], py[f], X, Y, prev[1 - f, 0], prev[1 - f, 1], model,
                       lik[f], cnt)
        seen[f] = cnt.max() > 0
        need[f] = normalise(lik[f], w[f]) < resample_fraction * N     # seed002 §III.D
    return vx, vy, px, py, lik, w, seen, need


@njit(cache=True)
def systematic_resample(w, u):
    """Indices of systematic resampling of normalised weights ``w`` with one uniform ``u``
    (Arulampalam et al. 2002, Algorithm 2): for each (i + u)/N the first cumulative weight
    ≥ it (``np.searchsorted``, side left), the last cumulative weight set to 1."""
    N = w.size
    c = np.empty(N)
    acc = 0.0
    for n in range(N):
        acc += w[n]
        c[n] = acc
    c[N - 1] = 1.0
    idx = np.empty(N, np.intp)
    k = 0
    for i in range(N):
        p = (i + u) / N
        while c[k] < p:
            k += 1
        idx[i] = k
    return idx


@njit(cache=True)
def resample_move(prev, dt, vx, vy, px, py, lik, w, legs, u_res, z_walk, u_mh, X, Y, model):
    """§III.D in place for the legs in ``legs`` (ascending): systematic resampling with
    ``u_res[r]``, a random walk ``z_walk[r]`` · walk_sd on the velocity, re-weighting, and
    Metropolis–Hastings acceptance with min(1, ω*/ω) from ``u_mh[r]``."""
    walk = model[11]
    N = vx.shape[1]
    lik_new, cnt = np.empty(N), np.empty(N, np.intp)
    vx_new, vy_new = np.empty(N), np.empty(N)
    px_new, py_new = np.empty(N), np.empty(N)
    for r in range(legs.size):
        f = legs[r]
        idx = systematic_resample(w[f], u_res[r])
        vx_f, vy_f, lik_f = vx[f][idx], vy[f][idx], lik[f][idx]
        for n in range(N):
            vx_new[n] = vx_f[n] + z_walk[r, n, 0] * walk[0]           # random walk on v
            vy_new[n] = vy_f[n] + z_walk[r, n, 1] * walk[1]
            px_new[n] = prev[f, 0] + vx_new[n] * dt                   # p = p̂_{k−1} + v Δt
            py_new[n] = prev[f, 1] + vy_new[n] * dt
        leg_likelihood(px_new, py_new, X, Y, prev[1 - f, 0], prev[1 - f, 1], model,
                       lik_new, cnt)
        for n in range(N):
            a = lik_f[n] <= 0.0 or u_mh[r, n] * lik_f[n] < lik_new[n]   # u < ω*/ω (MH)
            vx[f, n] = vx_new[n] if a else vx_f[n]
            vy[f, n] = vy_new[n] if a else vy_f[n]
            lik[f, n] = lik_new[n] if a else lik_f[n]
            px[f, n] = prev[f, 0] + vx[f, n] * dt
            py[f, n] = prev[f, 1] + vy[f, n] * dt
        normalise(lik[f], w[f])


@njit(cache=True)
def estimate(vx, vy, px, py, w, best_fraction):
    """§III.E: (2, 4) weighted mean (x, y, vx, vy) per leg of the particles with
    ω ≥ best_fraction · max ω (weights renormalised over them; sums as ``np.einsum``)."""
    N = w.shape[1]
    out = np.empty((2, 4))
    ws = np.empty(N)
    for f in range(2):
        thr = best_fraction * w[f].max()                              # seed002 §III.E
        for n in range(N):
            ws[n] = w[f, n] if w[f, n] >= thr else 0.0
        s = 0.0 + pairwise_sum(ws, 0, N)
        for n in range(N):
            ws[n] /= s
        a0 = a1 = a2 = a3 = 0.0
        for n in range(N):
            a0 += ws[n] * px[f, n]
            a1 += ws[n] * py[f, n]
            a2 += ws[n] * vx[f, n]
            a3 += ws[n] * vy[f, n]
        out[f, 0], out[f, 1], out[f, 2], out[f, 3] = a0, a1, a2, a3
    return out

