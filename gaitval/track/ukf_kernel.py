"""The UKF's per-sample cycle, compiled with numba (seed 003 §3.2, eq. 5–13).

Imported only by :func:`gaitval.track.ukf.run_toa_ukf` (lazily), so that no other job pays
numba's import.  :func:`ukf_steps` runs the predict–update–reflect cycle over a stretch of
samples and stops where the filter must be (re-)initialised by trilateration, which stays
in Python (:func:`gaitval.track.ukf.trilaterate_checked`: a few hundred calls in a study
against ~700,000 updates).  The code is the numpy formulation (``tests/ukf_numpy_reference.py``)
written with the same array expressions; numba compiles it (``@njit(cache=True)``, the
machine code cached beside this file or in ``NUMBA_CACHE_DIR``), ≈ 5× less CPU per sample
than running the same expressions in the interpreter.  Products are numba's ``@`` and the
factorisations ``np.linalg.cholesky`` / ``np.linalg.solve`` (BLAS and LAPACK of the
installed scipy): same input and machine, same bits; another BLAS build or CPU may round
the last digits differently (docs/numerics.md).

Two cases the paper leaves open are explicit: a covariance that stays indefinite after
symmetrising and a 1e-12 jitter, or an innovation covariance ``Pyy`` that is not positive
definite, skips the update and marks the filter lost (it re-initialises at the next
sample).  Neither occurred in the default study (0 of 677,301 updates, 2026-11-27).
"""
from __future__ import annotations

import numpy as np
from numba import njit

N = 6
#: chi_i - X = S B^T: the sigma-point pattern [0; I; -I] of seed003 eq. (7)
_S = np.vstack((np.zeros((1, N)), np.eye(N), -np.eye(N)))


@njit(cache=True)
def _cholesky(M):
    """Lower Cholesky factor of ``M``; an empty array when ``M`` is not positive definite."""
    try:
        return np.linalg.cholesky(M)
    except Exception:                              # numba: LinAlgError
        return np.empty((0, 0))


@njit(cache=True)
def _transition(dt, q):
    """``A`` and ``G W G^T`` of the constant-velocity model, seed003 eq. (5), W = diag(q)."""
    A = np.eye(N)
    G = np.zeros((N, 3))
    for c in range(3):
        A[c, 3 + c] = dt
        G[c, c] = 0.5 * dt * dt
        G[3 + c, c] = dt
    return A, (G * q) @ G.T


@njit(cache=True)
def _measurement_statistics(x, P, anchors, Wm, Wc, scale, V):
    """Sigma points from the predicted covariance and the measurement statistics.

    Returns ``P`` (symmetrised if its Cholesky factor failed), ``ybar`` (eq. 9), ``Pyy``,
    ``Pxy`` (eq. 10), and False when ``P`` is not positive definite (no update)."""
    B = _cholesky(scale * P)                               # seed003 eq. (7)
    if B.size == 0:
        P = 0.5 * (P + P.T) + 1e-12 * np.eye(N)
        B = _cholesky(scale * P)
        if B.size == 0:
            return P, np.empty(0), np.empty((0, 0)), np.empty((0, 0)), False
    dX = _S @ B.T                                          # chi_i - X, seed003 eq. (7)
    Y = np.empty((dX.shape[0], anchors.shape[0]))
    for i in range(dX.shape[0]):                           # Y_i = h(chi_i), seed003 eq. (6)
        for a in range(anchors.shape[0]):
            s = 0.0
            for c in range(3):
                s += (x[c] + dX[i, c] - anchors[a, c]) ** 2
            Y[i, a] = np.sqrt(s)
    ybar = Wm @ Y                                          # seed003 eq. (9)
    dY = Y - ybar
    WdY = Wc.reshape(-1, 1) * dY
    return P, ybar, dY.T @ WdY + V, dX.T @ WdY, True      # Pyy, Pxy: seed003 eq. (10)


@njit(cache=True)
def _gate(nu, Pyy, used, rejected, gate2, max_reject):
    """The per-anchor innovation gate (multipath, module notes of gaitval.track.ukf):
    drops (in ``used``, ``rejected``) the anchors with ``nu_j^2 > gate2 Pyy_jj`` when at
    most ``max_reject`` fail it; returns how many were dropped and whether more failed."""
    z2 = np.where(used, nu * nu / np.diag(Pyy), 0.0)
    bad = np.flatnonzero(z2 > gate2)
    if bad.size > max_reject:
        return 0, True                                     # a model mismatch: keep all
    used[bad] = False
    rejected[bad] = True
    return bad.size, False


@njit(cache=True)
def _update(x, P, nu, Pyy, Pxy, keep):
    """``K = Pxy Pyy^-1`` (eq. 10), ``X += K nu``, ``P -= K Pyy K^T`` (eq. 11) from the
    anchors ``keep``; False (no update) when their ``Pyy`` is not positive definite."""
    Pyy_s = np.ascontiguousarray(Pyy[keep][:, keep])
    Pxy_s = np.ascontiguousarray(Pxy[:, keep])
    if _cholesky(Pyy_s).size == 0:
        return x, P, False
    KT = np.linalg.solve(Pyy_s, np.ascontiguousarray(Pxy_s.T))     # K^T
    return x + nu[keep] @ KT, P - KT.T @ Pxy_s.T, True            # seed003 eq. (11)


@njit(cache=True)
def _reflect(x, normal, centre):
    """A state behind the receiver plane (the mirror image) reflected back, in place;
    True when it was."""
    h = np.dot(normal, x[:3] - centre)
    if h >= 0.0:
        return False
    x[:3] -= 2.0 * h * normal
    x[3:] -= 2.0 * np.dot(normal, x[3:]) * normal
    return True


@njit(cache=True)
def ukf_steps(k0, force, t, d, n_finite, model, x, P, starved, out):
    """Run the filter from sample ``k0`` (``x``, ``P``: the a-posteriori state of sample
    ``k0 - 1``) until it must be re-initialised or the log ends.

    Returns the index of the first sample that needs a re-initialisation (``starved ≥
    reinit_after`` at its start), or ``len(t)``; ``force``: run sample ``k0`` even if so
    (the caller's trilateration failed there).  ``model``: the tuple ``(anchors, Wm, Wc,
    scale, V, q, gate2, use_gate, max_reject, min_anchors, reinit_after, normal, centre)``
    (``normal`` empty: no mirror guard); ``out``: ``(x, P_diag, used, rejected,
    reflected)`` of :class:`gaitval.track.ukf.ToaUkfResult`, written row by row.
    ``x``, ``P``, ``starved[0]`` are updated in place.
    """
    (anchors, Wm, Wc, scale, V, q, gate2, use_gate, max_reject, min_anchors,
     reinit_after, normal, centre) = model
    out_x, out_P, used, rejected, reflected = out
    last_dt = np.nan
    A, Q = _transition(0.0, q)
    k = k0
    while k < t.shape[0]:
        if starved[0] >= reinit_after and not (force and k == k0):
            break
        dt = t[k] - t[k - 1]
        if dt != last_dt:
            A, Q = _transition(dt, q)
            last_dt = dt
        x[:] = A @ x                                       # X_{k+1/k} = A X_{k/k}
        P = A @ P @ A.T + Q                                # seed003 eq. (8), closed form
        lost = False
        if n_finite[k] == 0:
            starved[0] += 1
        else:
            P, ybar, Pyy, Pxy, ok = _measurement_statistics(x, P, anchors, Wm, Wc, scale, V)
            n_ok, mismatch = n_finite[k], False
            if ok:
                nu = d[k] - ybar
                if use_gate and np.any(nu * nu > gate2 * np.diag(Pyy)):
                    n_bad, mismatch = _gate(nu, Pyy, used[k], rejected[k], gate2,
                                            max_reject)
                    n_ok -= n_bad
                if n_ok > 0:
                    xn, P, ok = _update(x, P, nu, Pyy, Pxy, np.flatnonzero(used[k]))
                    x[:] = xn
                P = 0.5 * (P + P.T)
            lost = not ok
            starved[0] = starved[0] + 1 if (n_ok < min_anchors or mismatch) else 0
        # after an update, and after a prediction alone (no range, or none usable): a
        # state that coasts across the receiver plane is the mirror image too
        if normal.size and np.isfinite(x[0]):
            reflected[k] = _reflect(x, normal, centre)
        if lost or np.isnan(P[0, 0]) or abs(x[0]) > 1e3:  # numerically lost
            starved[0] = reinit_after
        out_x[k] = x
        out_P[k] = np.diag(P)
        k += 1
    return k, P
