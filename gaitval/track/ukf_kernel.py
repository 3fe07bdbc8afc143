"""The UKF's per-sample arithmetic, compiled with numba (seed 003 §3.2, eq. 5–13).

Imported only by :func:`gaitval.track.ukf.run_toa_ukf` (lazily), so that no other job pays
numba's import.  :func:`ukf_steps` runs the filter's predict–update–reflect cycle over a
stretch of samples and stops where the filter must be (re-)initialised by trilateration,
which stays in Python (:func:`gaitval.track.ukf.trilaterate`: a few hundred calls in a
study against ~700,000 updates).  The kernel is ``@njit(cache=True)`` without
``fastmath`` (IEEE arithmetic, no reassociation), its machine code cached beside this file
(``__pycache__`` or ``NUMBA_CACHE_DIR``).

The algebra is the numpy version's (gaitval ≤ 055770d) written as loops over the 6 state
components and the ``m`` anchors: the same equations in the same sequence, so the numbers
agree with it to round-off (the numpy version's 6×6 products ran in OpenBLAS, whose
summation order and fused multiply-adds are its own; tests/test_ukf_kernel.py bounds the
difference).  Two cases the numpy version left to LAPACK's undefined output are explicit
here: a covariance that stays indefinite after symmetrising and the jitter of eq. (7), or an
innovation covariance ``Pyy`` that is not positive definite, skips the update and marks the
filter lost (it re-initialises at the next sample).  Neither occurred in the default study
(0 of 677,301 updates, counted on 2026-11-27).
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

N = 6


@njit(cache=True)
def _cholesky(M, L):
    """Lower Cholesky factor of the symmetric ``M`` into ``L``; False if not positive
    definite (a pivot ≤ 0 or NaN).  Reads the lower triangle, as LAPACK's ``dpotrf``."""
    n = M.shape[0]
    for j in range(n):
        s = M[j, j]
        for c in range(j):
            s -= L[j, c] * L[j, c]
        if not s > 0.0:
            return False
        d = math.sqrt(s)
        L[j, j] = d
        for i in range(j + 1, n):
            v = M[i, j]
            for c in range(j):
                v -= L[i, c] * L[j, c]
            L[i, j] = v / d
        for i in range(j):
            L[i, j] = 0.0
    return True


@njit(cache=True)
def _chol_solve(L, B, n):
    """``B[:n] <- (L L^T)^-1 B[:n]`` in place, column by column (``L`` n×n lower)."""
    for c in range(B.shape[1]):
        for i in range(n):                     # L y = b
            v = B[i, c]
            for j in range(i):
                v -= L[i, j] * B[j, c]
            B[i, c] = v / L[i, i]
        for i in range(n - 1, -1, -1):         # L^T z = y
            v = B[i, c]
            for j in range(i + 1, n):
                v -= L[j, i] * B[j, c]
            B[i, c] = v / L[i, i]


@njit(cache=True)
def ukf_steps(k0, force, t, d, n_finite, anchors, Wm, Wc, scale, Vm, Q4, Q3, Q2,
              gate2, use_gate, max_reject, min_anchors, reinit_after, normal, centre,
              has_normal, x, P, starved_box, out_x, out_P, used, rejected, reflected):
    """Run the filter from sample ``k0`` (the state ``x``, ``P`` is the a-posteriori one
    of sample ``k0 - 1``) until the filter must be re-initialised or the log ends.

    Returns the index of the first sample that needs a re-initialisation (``starved ≥
    reinit_after`` at its start), or ``len(t)``; ``force``: run sample ``k0`` even if so
    (the caller's trilateration failed there).  Updates ``x``, ``P``, ``starved_box[0]``
    and the output rows ``out_x``, ``out_P`` (a-posteriori state and covariance diagonal),
    ``used``, ``rejected`` and ``reflected`` in place.  Per sample (module notes of
    :mod:`gaitval.track.ukf`): predict (eq. 8 closed form), the measurement sigma points
    and statistics (eq. 7, 9, 10), the per-anchor gate, the update from the anchors kept
    (eq. 10–11), the mirror reflection.
    """
    n_s = t.shape[0]
    m = anchors.shape[0]
    starved = starved_box[0]
    A = np.eye(N)
    Q = np.zeros((N, N))
    AP = np.empty((N, N))
    Pn = np.empty((N, N))
    L = np.zeros((N, N))
    dX = np.zeros((2 * N + 1, N))
    Ysig = np.empty((2 * N + 1, m))
    ybar = np.empty(m)
    WdY = np.empty((2 * N + 1, m))
    Pyy = np.empty((m, m))
    Pxy = np.empty((N, m))
    nu = np.empty(m)
    keep = np.empty(m, dtype=np.int64)
    Ps = np.empty((m, m))
    Ls = np.zeros((m, m))
    KT = np.empty((m, N))
    last_dt = np.nan
    k = k0
    while k < n_s:
        if starved >= reinit_after and not (force and k == k0):
            break
        dt = t[k] - t[k - 1]
        if dt != last_dt:                      # seed003 eq. (5): A = I + dt E, G W G^T
            last_dt = dt
            A[0, 3] = A[1, 4] = A[2, 5] = dt
            c4, c3, c2 = 0.25 * dt ** 4, 0.5 * dt ** 3, dt * dt
            for i in range(N):
                for j in range(N):
                    Q[i, j] = c4 * Q4[i, j] + c3 * Q3[i, j] + c2 * Q2[i, j]
        # X_{k+1/k} = A X_{k/k};  P = A P A^T + G W G^T, seed003 eq. (8) (closed form)
        for i in range(3):
            x[i] = x[i] + dt * x[i + 3]
        for i in range(N):
            for j in range(N):
                v = 0.0
                for c in range(N):
                    v += A[i, c] * P[c, j]
                AP[i, j] = v
        for i in range(N):
            for j in range(N):
                v = 0.0
                for c in range(N):
                    v += AP[i, c] * A[j, c]
                Pn[i, j] = v + Q[i, j]
        P[:, :] = Pn
        if n_finite[k] == 0:
            starved += 1
        else:
            lost = False
            # sigma points chi = X + [0, B, -B] columns, B = chol((n + lambda) P), eq. (7)
            for i in range(N):
                for j in range(N):
                    Pn[i, j] = scale * P[i, j]
            if not _cholesky(Pn, L):
                for i in range(N):
                    for j in range(N):
                        P[i, j] = 0.5 * (P[i, j] + P[j, i])
                    P[i, i] += 1e-12
                for i in range(N):
                    for j in range(N):
                        Pn[i, j] = scale * P[i, j]
                lost = not _cholesky(Pn, L)
            if not lost:
                for i in range(N):
                    for j in range(N):
                        dX[1 + i, j] = L[j, i]
                        dX[1 + N + i, j] = -L[j, i]
                for i in range(2 * N + 1):          # Y_i = h(chi_i), seed003 eq. (6)
                    for a in range(m):
                        s = 0.0
                        for c in range(3):
                            e = (x[c] + dX[i, c]) - anchors[a, c]
                            s += e * e
                        Ysig[i, a] = math.sqrt(s)
                for a in range(m):                   # seed003 eq. (9)
                    v = 0.0
                    for i in range(2 * N + 1):
                        v += Wm[i] * Ysig[i, a]
                    ybar[a] = v
                    for i in range(2 * N + 1):
                        Ysig[i, a] -= v              # dY
                        WdY[i, a] = Wc[i] * Ysig[i, a]
                for a in range(m):                   # seed003 eq. (10)
                    for b in range(m):
                        v = 0.0
                        for i in range(2 * N + 1):
                            v += Ysig[i, a] * WdY[i, b]
                        Pyy[a, b] = v + Vm[a, b]
                    for c in range(N):
                        v = 0.0
                        for i in range(2 * N + 1):
                            v += dX[i, c] * WdY[i, a]
                        Pxy[c, a] = v
                    nu[a] = d[k, a] - ybar[a]
                # the per-anchor gate (multipath, module notes of gaitval.track.ukf)
                n_ok = n_finite[k]
                mismatch = False
                if use_gate:
                    over = False
                    for a in range(m):
                        if nu[a] * nu[a] > gate2 * Pyy[a, a]:
                            over = True
                    if over:
                        n_bad = 0
                        for a in range(m):
                            z = abs(nu[a]) / math.sqrt(Pyy[a, a]) if used[k, a] else 0.0
                            if z * z > gate2:
                                keep[n_bad] = a
                                n_bad += 1
                        if n_bad <= max_reject:
                            for b in range(n_bad):
                                rejected[k, keep[b]] = True
                                used[k, keep[b]] = False
                            n_ok -= n_bad
                        else:
                            mismatch = True
                if n_ok > 0:                         # K = Pxy Pyy^-1, seed003 eq. (10)
                    ns = 0
                    for a in range(m):
                        if used[k, a]:
                            keep[ns] = a
                            ns += 1
                    for a in range(ns):
                        for b in range(ns):
                            Ps[a, b] = Pyy[keep[a], keep[b]]
                        for c in range(N):
                            KT[a, c] = Pxy[c, keep[a]]
                    if _cholesky(Ps[:ns, :ns], Ls[:ns, :ns]):
                        _chol_solve(Ls[:ns, :ns], KT, ns)
                        for c in range(N):           # X += K (d - Y), seed003 eq. (11)
                            v = 0.0
                            for a in range(ns):
                                v += nu[keep[a]] * KT[a, c]
                            x[c] += v
                        for i in range(N):           # P -= K Pyy K^T, seed003 eq. (11)
                            for j in range(N):
                                v = 0.0
                                for a in range(ns):
                                    v += KT[a, i] * Pxy[j, keep[a]]
                                P[i, j] -= v
                    else:
                        lost = True
                for i in range(N):
                    for j in range(i, N):
                        v = 0.5 * (P[i, j] + P[j, i])
                        P[i, j] = v
                        P[j, i] = v
                if has_normal:                       # the mirror image of a planar array
                    h = 0.0
                    for c in range(3):
                        h += normal[c] * (x[c] - centre[c])
                    if h < 0.0:
                        hv = 0.0
                        for c in range(3):
                            hv += normal[c] * x[3 + c]
                        for c in range(3):
                            x[c] -= 2.0 * h * normal[c]
                            x[3 + c] -= 2.0 * hv * normal[c]
                        reflected[k] = True
                starved = starved + 1 if (n_ok < min_anchors or mismatch) else 0
            p00 = P[0, 0]
            if lost or p00 != p00 or abs(x[0]) > 1e3:       # numerically lost
                starved = reinit_after
        for c in range(N):
            out_x[k, c] = x[c]
            out_P[k, c] = P[c, c]
        k += 1
    starved_box[0] = starved
    return k
