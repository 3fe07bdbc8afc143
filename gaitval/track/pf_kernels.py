"""The particle filter's per-scan arithmetic, compiled with numba (seed 002 §III.B–E).

Imported only by the PF (lazily, from :mod:`gaitval.track.pf` and
:func:`gaitval.track.pf_likelihood.likelihood`), so that no other job pays numba's import.
Every kernel is ``@njit(cache=True)`` without ``fastmath``: IEEE arithmetic, no
reassociation and no contraction into fused multiply-adds (the only ones are the explicit
``llvm.fma`` of :func:`libc_exp`), and the compiled machine code is cached beside this
file (``__pycache__``, or ``NUMBA_CACHE_DIR``), so a process pays numba's import and the
loading of the cached kernels once, not a compilation (docs/rollator.md, "Speed").

Same numbers as the vectorised numpy version these kernels replace (gaitval ≤ ddd5125),
bit for bit:

* random draws are not made here: :mod:`gaitval.track.pf` draws them with the
  ``numpy.random.Generator`` in the same order and shapes as before and passes them in;
* ``log``, ``sqrt``, ``hypot`` and β's ``exp`` are the C library's, as numpy's are for
  float64 on x86-64 without AVX-512 (numpy's AVX-512 ``exp``/``log`` may differ in the last
  bit); the pair densities' ``exp`` is the C library's algorithm inlined
  (:func:`libc_exp`, bit-equal to glibc's x86-64 ``exp``; other C libraries may round a
  last bit differently, and so would numpy there);
* sums keep numpy's order: the region sums add the pairs particle-major, point ascending
  (``np.bincount``); row sums are numpy's pairwise summation (:func:`pairwise_sum`); the
  weighted means add sequentially from 0 (``np.einsum``); the four-region dot product is
  (R1 + R4) + (R2 + R3) in pair-code order 0, 2, 1, 3 — the order OpenBLAS's x86-64 ``dgemv``
  used for ``means @ pi`` (a fixed order here, on every machine).
"""
from __future__ import annotations

import math
import struct
from fractions import Fraction

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

#: numpy's block size of pairwise summation (numpy/_core/src/umath/loops_utils.h.src)
_PW_BLOCK = 128


# -- exp: the C library's algorithm, inlined ---------------------------------------------------
@intrinsic
def _fma(typingctx, a, b, c):
    """IEEE fused multiply-add a·b + c, one rounding (``llvm.fma.f64``)."""
    def codegen(context, builder, signature, args):
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]),
                                            "llvm.fma.f64")
        return builder.call(fn, args)
    return types.float64(types.float64, types.float64, types.float64), codegen


@intrinsic
def _bits(typingctx, a):
    """The bits of a float64 as uint64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.IntType(64))
    return types.uint64(types.float64), codegen


@intrinsic
def _double(typingctx, a):
    """A uint64's bits as float64."""
    def codegen(context, builder, signature, args):
        return builder.bitcast(args[0], ir.DoubleType())
    return types.float64(types.uint64), codegen


def _exp_table() -> np.ndarray:
    """2^(i/128) = H_i·(1 + T_i), i < 128: [bits(T_i), bits(H_i) − (i << 45)] per i, H_i the
    nearest double, T_i the nearest double to the relative rest (the table of glibc's and
    musl's exp, ``__exp_data.tab``; computed here from a 200-bit 2^(1/128))."""
    P = 200
    base = 1 << (1 + 128 * P)
    for _ in range(7):
        base = math.isqrt(base)                       # 2^(1/128)·2^P, error < 2^-190
    bits = lambda d: struct.unpack("<Q", struct.pack("<d", d))[0]   # noqa: E731
    tab, acc = np.empty(256, np.uint64), 1 << P
    for i in range(128):
        t = Fraction(acc, 1 << P)
        H = float(t)
        tab[2 * i] = bits(float((t - Fraction(H)) / Fraction(H)))
        tab[2 * i + 1] = (bits(H) - (i << 45)) % 2 ** 64
        acc = acc * base >> P
    return tab


_EXP_TAB = _exp_table()
_INVLN2N = float.fromhex("0x1.71547652b82fep0") * 128      # N/ln2, N = 128
_NEGLN2HIN = -float.fromhex("0x1.62e42fefa0000p-8")         # −ln2/N, high part
_NEGLN2LON = -float.fromhex("0x1.cf79abc9e3b3ap-47")        # −ln2/N, low part
_SHIFT = float.fromhex("0x1.8p52")
_C2, _C3, _C4, _C5 = (float.fromhex(h) for h in (
    "0x1.ffffffffffdbdp-2", "0x1.555555555543cp-3", "0x1.55555cf172b91p-5",
    "0x1.1111167a4d017p-7"))


@njit(cache=True)
def libc_exp(x):
    """exp(x), bit for bit the value of glibc ≥ 2.28's ``exp`` on x86-64 with FMA (the one
    ``np.exp`` and ``math.exp`` call here): ARM's optimized-routines algorithm, x = k ln2/128
    + r, 2^(k/128) from the table, exp(r) − 1 by a degree-5 polynomial, with glibc's fused
    multiply-adds.  Inlined, about twice as fast as the library call; |x| outside
    [2^-54, 512) and NaN go to the library (``math.exp``).  tests/test_pf_kernel.py checks it
    against ``np.exp``."""
    ax = abs(x)
    if not (ax < 512.0 and ax >= 5.551115123125783e-17):       # 2^-54 ≤ |x| < 512
        return math.exp(x)
    kd = _INVLN2N * x + _SHIFT
    ki = _bits(kd)
    kd -= _SHIFT
    r = _fma(kd, _NEGLN2LON, _fma(kd, _NEGLN2HIN, x))
    i = (ki & np.uint64(127)) << np.uint64(1)
    tail = _double(_EXP_TAB[i])
    scale = _double(_EXP_TAB[i + np.uint64(1)] + (ki << np.uint64(45)))
    r2 = r * r
    tmp = _fma(r2 * r2, _fma(r, _C5, _C4), _fma(r2, _fma(r, _C3, _C2), tail + r))
    return _fma(scale, tmp, scale)


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


#: row k: which region sum a pair of code k adds to (row 4: a pair outside the window)
_ONE_HOT = np.vstack([np.eye(4), np.zeros((1, 4))])


@njit(cache=True, inline="always")
def _pair_exponents(pxi, pyi, Xn, Yn, hx, hy, abc, x, code, ki, r):
    """For particle (pxi, pyi) and each point j: ``code[j]`` the pair code (4: outside the
    window's near half), ``x[j]`` the exponent of the pair's normal density (−1 outside), and
    the first, table-free half of :func:`libc_exp` of it (``ki``, ``r``).
    Branch-free, so that it vectorises."""
    A0, A1, A2, A3 = abc[0, 0], abc[1, 0], abc[2, 0], abc[3, 0]
    B0, B1, B2, B3 = abc[0, 1], abc[1, 1], abc[2, 1], abc[3, 1]
    C0, C1, C2, C3 = abc[0, 2], abc[1, 2], abc[2, 2], abc[3, 2]
    for j in range(Xn.size):
        u = pxi - Xn[j]
        v = pyi - Yn[j]
        av = abs(v)
        inside = (u > 0.0) & (u <= hx) & (av <= hy)                 # window ∩ lower half
        inner, left = av < u, v >= 0.0                                # seed002 §III.C R_m
        A = (A3 if inner else A2) if left else (A1 if inner else A0)
        B = (B3 if inner else B2) if left else (B1 if inner else B0)
        C = (C3 if inner else C2) if left else (C1 if inner else C0)
        d2 = u * u + v * v
        e = A * d2 + B * math.sqrt(d2) + C                            # ln N(d | μ_Rm, Σ_Rm)
        e = e if inside else -1.0
        x[j] = e
        code[j] = (inner + 2 * left) if inside else 4
        kd = _INVLN2N * e + _SHIFT                                    # libc_exp, first half
        ki[j] = _bits(kd)
        kd -= _SHIFT
        r[j] = _fma(kd, _NEGLN2LON, _fma(kd, _NEGLN2HIN, e))


@njit(cache=True)
def leg_likelihood(px, py, X, Y, ox, oy, model, lik, cnt):
    """Unnormalised p(y|x) of one leg's particles into ``lik``, contour counts into ``cnt``
    (seed002 §III.C; formula in :func:`gaitval.track.pf_likelihood.likelihood`).

    ``model``: :attr:`gaitval.track.pf_likelihood.PFArrays.kernel`.  A pair (particle i,
    point j) with u = px_i − X_j, v = py_i − Y_j is in the window's near half when
    0 < u ≤ h_x and |v| ≤ h_y; its pair code is [|v| < u] + 2·[v ≥ 0] (R1, R2, R4, R3).
    Each region's densities are added point ascending from 0; a pair outside the window or
    in another region adds +0.0 (exact: the sums are ≥ +0 and every density is finite,
    its exponent being ≤ ln(1/(σ√2π)) since A < 0).
    """
    _, _, _, hx, hy, abc, pi, count_pdf, g_a, g_scale, g_lognorm, _ = model
    near = near_points(X, Y, px, py, hx, hy)
    Xn, Yn = X[near], Y[near]
    M = Xn.size
    x, r = np.empty(M), np.empty(M)
    code, ki = np.empty(M, np.intp), np.empty(M, np.uint64)
    one, tab = _ONE_HOT, _EXP_TAB
    top = count_pdf.size - 1
    for i in range(px.size):
        _pair_exponents(px[i], py[i], Xn, Yn, hx, hy, abc, x, code, ki, r)
        s0 = s1 = s2 = s3 = 0.0                                       # Σ densities per code
        for j in range(M):                                            # point ascending
            ax = abs(x[j])
            if ax < 512.0 and ax >= 5.551115123125783e-17:            # libc_exp, 2nd half
                t = (ki[j] & np.uint64(127)) << np.uint64(1)
                scale = _double(tab[t + np.uint64(1)] + (ki[j] << np.uint64(45)))
                rj = r[j]
                rr = rj * rj
                tmp = _fma(rr * rr, _fma(rj, _C5, _C4), _fma(rr, _fma(rj, _C3, _C2),
                                                             _double(tab[t]) + rj))
                dens = _fma(scale, tmp, scale)                        # N(d | μ_Rm, Σ_Rm)
            else:
                dens = math.exp(x[j])
            c = code[j]
            s0 += dens * one[c, 0]
            s1 += dens * one[c, 1]
            s2 += dens * one[c, 2]
            s3 += dens * one[c, 3]
        n0 = n1 = n2 = n3 = 0                                         # points per code
        for j in range(M):
            n0 += code[j] == 0
            n1 += code[j] == 1
            n2 += code[j] == 2
            n3 += code[j] == 3
        m0, m1 = s0 / max(n0, 1.0), s1 / max(n1, 1.0)                 # mean per region
        m2, m3 = s2 / max(n2, 1.0), s3 / max(n3, 1.0)
        region = (m0 * pi[0] + m2 * pi[2]) + (m1 * pi[1] + m3 * pi[3])   # Σ_m π_Rm N(...)
        n = n0 + n1 + n2 + n3
        lam = count_pdf[min(n, top)]                                  # λ_i
        d = math.hypot(px[i] - ox, py[i] - oy)
        beta = 0.0                                                    # β_i: Gamma pdf
        if d > 0.0:
            beta = math.exp((g_a - 1.0) * math.log(d) - d / g_scale - g_lognorm)
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
