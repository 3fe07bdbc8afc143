"""The UKF's numpy formulation (gaitval ≤ 055770d), kept as the reference of its kernel.

:func:`run_toa_ukf` here is ``gaitval.track.ukf.run_toa_ukf`` as it was before the
per-sample cycle moved into numba (:mod:`gaitval.track.ukf_kernel`), verbatim: each product
is numpy's ``@``, the factorisations scipy's LAPACK.  tests/test_ukf.py runs both on the
same ranges and requires the same decisions and states equal within round-off
(docs/numerics.md).  One change since: the (re-)initialisation is the checked
trilateration both use (issue 34).
"""
from __future__ import annotations

import numpy as np

from gaitval.track.ukf import (N_STATE, ToaUkfResult, _mirror_plane, trilaterate_checked,
                               ukf_weights)

_NO_ANCHOR = np.zeros(0, dtype=np.intp)


def run_toa_ukf(t: np.ndarray, d: np.ndarray, anchors: np.ndarray, *,
                W_sigma: np.ndarray, V: np.ndarray, alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0, init_guess: np.ndarray | None = None,
                init_sigma_pos: float = 0.05, init_sigma_vel: float = 1.0,
                gate_sigma: float = 4.0, max_reject: int = 2, min_anchors: int = 3,
                reinit_after: int = 10, mirror_guard: bool = True) -> ToaUkfResult:
    """The numpy formulation of :func:`gaitval.track.ukf.run_toa_ukf` (same parameters,
    same result type), as of gaitval 055770d."""
    t = np.asarray(t, dtype=float)
    d = np.asarray(d, dtype=float)
    anchors = np.asarray(anchors, dtype=float)
    n_s = len(d)
    mdl = _Model(anchors, W_sigma, V, alpha, beta, kappa, gate_sigma, max_reject)
    guess = anchors.mean(axis=0) if init_guess is None else np.asarray(init_guess, float)
    normal, centre = _mirror_plane(anchors, guess, mirror_guard and init_guess is not None)
    P0 = np.diag([init_sigma_pos ** 2] * 3 + [init_sigma_vel ** 2] * 3)
    finite = np.isfinite(d)
    n_finite = finite.sum(axis=1)
    res = ToaUkfResult.start(finite)
    x = P = last_dt = None
    starved = 0
    for k in range(n_s):
        if x is None or starved >= reinit_after:
            # from the guess: its side of the array (issue 34: checked, as the kernel's caller)
            fix = trilaterate_checked(d[k], anchors, guess)
            p0 = fix.p
            if np.all(np.isfinite(p0)):
                res.used[k] = fix.used
                x, P, starved = np.concatenate([p0, np.zeros(3)]), P0.copy(), 0
                res.reinit[k] = True
                res.x[k], res.P_diag[k] = x, P.diagonal()
                continue
            if x is None:
                res.used[k] = False
                continue                       # wait for a sample with >= 3 ranges
        dt = t[k] - t[k - 1]
        if dt != last_dt:
            A, AT, Q = mdl.transition(dt)
            last_dt = dt
        x = A @ x                                                # X_{k+1/k} = A X_{k/k}
        P = A @ P @ AT + Q                               # A P A^T + G W G^T, seed003 eq. (8)
        if n_finite[k] == 0:
            starved += 1
        else:
            x, P, n_ok, mismatch = _update(mdl, x, P, d[k], int(n_finite[k]), res, k)
            if normal is not None:
                x, res.reflected[k] = _reflect(x, normal, centre)
            starved = starved + 1 if (n_ok < min_anchors or mismatch) else 0
            p00 = P[0, 0]
            if p00 != p00 or abs(x[0]) > 1e3:                     # numerically lost
                starved = reinit_after
        res.x[k], res.P_diag[k] = x, P.diagonal()
    return res


class _Model:
    """The constant pieces of one run: weights (eq. 12–13), noises, eq. (5) and the gate."""

    def __init__(self, anchors, W_sigma, V, alpha, beta, kappa, gate_sigma, max_reject):
        # LAPACK's Cholesky and SPD solve, imported here: importing the tracker roles (the
        # workflow does at parse time) should not pay for scipy.linalg
        from scipy.linalg.lapack import dposv, dpotrf

        self.potrf, self.posv = dpotrf, dposv
        self.anchors = anchors
        self.Wm, Wc, lam = ukf_weights(N_STATE, alpha, beta, kappa)
        self.Wc_col = Wc[:, None]
        self.scale = N_STATE + lam
        V = np.asarray(V, dtype=float)
        self.Vm = np.diag(V) if V.ndim == 1 else V
        self.I6 = I6 = np.eye(N_STATE)
        # chi_i - X = S B^T, seed003 eq. (7)
        self.S = np.vstack([np.zeros((1, N_STATE)), I6, -I6])
        # seed003 eq. (5): A = I + dt E,  G W G^T = dt^4/4 Q4 + dt^3/2 Q3 + dt^2 Q2,
        # W = diag(q)
        q = np.asarray(W_sigma, dtype=float) ** 2
        self.E = np.zeros((N_STATE, N_STATE))
        self.E[0, 3] = self.E[1, 4] = self.E[2, 5] = 1.0
        self.Q4, self.Q3, self.Q2 = (np.zeros((N_STATE, N_STATE)) for _ in range(3))
        self.Q4[:3, :3] = np.diag(q)
        self.Q3[:3, 3:] = self.Q3[3:, :3] = np.diag(q)
        self.Q2[3:, 3:] = np.diag(q)
        self.gate2 = float(gate_sigma) ** 2
        self.use_gate = bool(np.isfinite(gate_sigma))
        self.max_reject = max_reject
        self._transitions: dict = {}

    def transition(self, dt: float):
        """``A``, ``A^T`` and ``G W G^T`` of eq. (5) for one time step (read-only arrays,
        remembered per ``dt``: a log's steps take a handful of distinct values, e.g. 16 in
        a 15,000-sample treadmill trial whose step changes 9,852 times)."""
        hit = self._transitions.get(dt)
        if hit is None:
            A = self.I6 + dt * self.E
            Q = (0.25 * dt ** 4) * self.Q4 + (0.5 * dt ** 3) * self.Q3 + (dt * dt) * self.Q2
            A.flags.writeable = Q.flags.writeable = False
            hit = (A, A.T, Q)
            if len(self._transitions) < 4096:
                self._transitions[dt] = hit
        return hit


def _sigma_statistics(mdl: _Model, x: np.ndarray, P: np.ndarray):
    """Sigma points from the predicted covariance and the measurement statistics.

    Returns ``P`` (symmetrised if its Cholesky factor failed), ``ybar`` (eq. 9) and
    ``Pyy``, ``Pxy`` (eq. 10).
    """
    B, info = mdl.potrf(mdl.scale * P, lower=1)           # seed003 eq. (7)
    if info != 0:
        P = 0.5 * (P + P.T) + 1e-12 * mdl.I6
        B, info = mdl.potrf(mdl.scale * P, lower=1)
    dX = mdl.S @ B.T
    diff = (x[:3] + dX[:, :3])[:, None, :] - mdl.anchors
    Ysig = np.sqrt((diff * diff).sum(axis=2))        # Y_i = h(chi_i), seed003 eq. (6)
    ybar = mdl.Wm @ Ysig                                 # seed003 eq. (9)
    dY = Ysig - ybar
    WdY = mdl.Wc_col * dY
    Pyy = dY.T @ WdY + mdl.Vm                            # seed003 eq. (10)
    Pxy = dX.T @ WdY                                     # seed003 eq. (10)
    return P, ybar, Pyy, Pxy


def _gate(mdl: _Model, nu: np.ndarray, Pyy: np.ndarray, finite: np.ndarray):
    """Per-anchor innovation gate (multipath, module notes), once some ``|nu_j|`` exceeds
    ``gate_sigma sqrt(Pyy_jj)``: the anchors to drop and whether more than ``max_reject``
    failed (then none is dropped: the motion model, not multipath, is the likely culprit).
    """
    z = np.abs(nu) / np.sqrt(Pyy.diagonal())
    z[~finite] = 0.0
    bad = np.flatnonzero(z * z > mdl.gate2)
    return (bad, False) if bad.size <= mdl.max_reject else (_NO_ANCHOR, True)


def _update(mdl: _Model, x, P, dk, n_ok: int, res: ToaUkfResult, k: int):
    """A-posteriori statistics (eq. 9–11) from the anchors that pass the gate.

    Sigma points ``chi = [X, X + B, X - B]`` with ``B = chol((n + lambda) P)``,
    ``Y_i = h(chi_i)`` (eq. 6), ``Pyy = sum Wc (Y_i - Y)(Y_i - Y)^T + V``,
    ``Pxy = sum Wc (chi_i - X)(Y_i - Y)^T``, ``K = Pxy Pyy^-1``, ``X += K (d - Y)``,
    ``P -= K Pyy K^T``.  Marks the dropped anchors in ``res``; returns ``x``, ``P``, the
    number of anchors used and whether the gate saw a model mismatch.
    """
    P, ybar, Pyy, Pxy = _sigma_statistics(mdl, x, P)
    nu = dk - ybar
    bad, mismatch = _NO_ANCHOR, False
    if mdl.use_gate and (nu * nu > mdl.gate2 * Pyy.diagonal()).any():
        bad, mismatch = _gate(mdl, nu, Pyy, res.used[k])
    if bad.size:
        res.rejected[k, bad] = True
        res.used[k, bad] = False
        n_ok -= bad.size
    if n_ok == len(dk):
        _, KT, info = mdl.posv(Pyy, Pxy.T)               # K = Pxy Pyy^-1, seed003 eq. (10)
        x = x + nu @ KT                                  # seed003 eq. (11)
        P = P - KT.T @ Pxy.T                             # P - K Pyy K^T, seed003 eq. (11)
    elif n_ok > 0:
        s = np.flatnonzero(res.used[k])
        Pxy_s = Pxy[:, s]
        _, KT, info = mdl.posv(Pyy[np.ix_(s, s)], Pxy_s.T)
        x = x + nu[s] @ KT
        P = P - KT.T @ Pxy_s.T
    P += P.T
    P *= 0.5
    return x, P, n_ok, mismatch


def _reflect(x: np.ndarray, normal: np.ndarray, centre: np.ndarray):
    """A state behind the receiver plane (the mirror image) reflected back; and whether."""
    h = normal @ (x[:3] - centre)
    if h < 0.0:
        x = x.copy()
        x[:3] -= 2.0 * h * normal
        x[3:] -= 2.0 * (normal @ x[3:]) * normal
        return x, True
    return x, False
