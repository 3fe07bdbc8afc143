"""Unscented Kalman filter for time-of-arrival (TOA) ranging: constant-velocity model.

The filter follows seed 003 §3.2 line by line: state ``[x y z vx vy vz]`` (eq. 3), linear
constant-velocity transition with acceleration noise (eq. 4–5), range measurement to each
receiver (anchor) (eq. 6), scaled sigma points (eq. 7, 12, 13), a-priori statistics (eq. 8),
measurement sigma points drawn again from the predicted covariance (eq. 9), gain (eq. 10)
and a-posteriori statistics (eq. 11).

Two things the paper leaves open are made explicit here:

* **Per-anchor outlier handling (multipath).**  A late echo (a reflected path) makes one
  receiver's range too long while the others stay good.  Before the update, each anchor's
  innovation ``nu_j = d_j - y_j`` is normalised by its predicted standard deviation
  ``sqrt(Pyy_jj)`` (eq. 10); the anchors whose ``|nu_j| / sqrt(Pyy_jj)`` exceeds
  ``gate_sigma`` are dropped from this update (their rows and columns are removed from
  ``Pyy`` and ``Pxy``) when there are at most ``max_reject`` of them.  When more anchors
  disagree at once, the motion model, not multipath, is the likely culprit (e.g. the heel
  stopping abruptly at heel strike), and all measurements are kept.  When fewer than
  ``min_anchors`` anchors were usable, or more than ``max_reject`` failed the gate, for
  ``reinit_after`` consecutive steps (the filter has lost the transmitter), the state is
  re-initialised by trilateration.  A missing echo (NaN) drops that anchor like a gated one.
* **The mirror solution of a planar array.**  Four receivers in one plane (the paper's
  p1..p4) cannot tell a transmitter in front of the plane from its mirror image behind it;
  the ranges fit both equally.  After an abrupt manoeuvre the linearised update can carry
  the state through the plane, and it then tracks the mirror image.  When the anchors are
  coplanar, the side of ``init_guess`` is taken as the physical side (the transmitter faces
  the receivers) and a state that ends an update on the other side is reflected back
  (position and velocity); this is counted in ``reflected``.
* **The a-priori step for a linear model.**  Passing sigma points through the linear
  transition ``A`` (eq. 8) gives exactly ``A P A^T`` (the unscented transform is exact for
  linear maps), so eq. (8) is evaluated in that closed form, which is cheaper and free of
  the round-off of the large negative weight ``W_0`` that ``alpha = 1e-3`` produces.

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.linalg.lapack import dposv as _posv, dpotrf as _potrf

N_STATE = 6


def ukf_weights(n: int = N_STATE, alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """Sigma-point weights of the scaled unscented transform.

    Parameters
    ----------
    n : int
        State dimension.
    alpha, beta, kappa : float
        Spread, prior-distribution and secondary scaling parameters (seed 003 uses
        ``1e-3``, ``2``, ``0``).

    Returns
    -------
    Wm, Wc : ndarray, shape (2n+1,)
        Weights of the mean and of the covariance.
    lam : float
        The scaling factor lambda.

    Notes
    -----
    ``lambda = alpha^2 (n + kappa) - n`` (eq. 13);
    ``W0m = lambda/(n+lambda)``, ``W0c = lambda/(n+lambda) + 1 - alpha^2 + beta``,
    ``Wim = Wic = 1/(2(n+lambda))`` (eq. 12).
    """
    lam = alpha ** 2 * (n + kappa) - n                       # eq. (13)
    Wm = np.full(2 * n + 1, 1.0 / (2.0 * (n + lam)))          # eq. (12)
    Wc = Wm.copy()
    Wm[0] = lam / (n + lam)
    Wc[0] = lam / (n + lam) + 1.0 - alpha ** 2 + beta
    return Wm, Wc, lam


def cv_matrices(dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Transition ``A`` and noise gain ``G`` of the constant-velocity model (eq. 5)."""
    A = np.eye(N_STATE)
    A[0, 3] = A[1, 4] = A[2, 5] = dt
    G = np.zeros((N_STATE, 3))
    G[0, 0] = G[1, 1] = G[2, 2] = 0.5 * dt * dt
    G[3, 0] = G[4, 1] = G[5, 2] = dt
    return A, G


def toa_ranges(pos: np.ndarray, anchors: np.ndarray) -> np.ndarray:
    """Ranges from positions ``(..., 3)`` to anchors ``(m, 3)`` -> ``(..., m)`` (eq. 6)."""
    diff = pos[..., None, :] - anchors
    return np.sqrt(np.einsum("...ij,...ij->...i", diff, diff))


def trilaterate(d: np.ndarray, anchors: np.ndarray, guess: np.ndarray,
                n_iter: int = 20) -> np.ndarray:
    """Least-squares position from ranges (Gauss–Newton from ``guess``).

    With a planar receiver array there are two mirror solutions; Gauss–Newton converges to
    the one on the side of ``guess``.  NaN ranges are ignored.  Returns NaN positions when
    fewer than three ranges are finite.
    """
    ok = np.isfinite(d)
    if ok.sum() < 3:
        return np.full(3, np.nan)
    a, r = anchors[ok], d[ok]
    p = np.asarray(guess, dtype=float).copy()
    for _ in range(n_iter):
        diff = p - a
        rng = np.linalg.norm(diff, axis=1)
        J = diff / np.maximum(rng, 1e-9)[:, None]
        step, *_ = np.linalg.lstsq(J, r - rng, rcond=None)
        p = p + step
        if np.linalg.norm(step) < 1e-10:
            break
    return p


@dataclass
class ToaUkfResult:
    """What :func:`run_toa_ukf` returns (arrays aligned with the input samples).

    Attributes
    ----------
    x : ndarray, shape (n, 6)
        A-posteriori state ``[x y z vx vy vz]`` (metres, m/s) per sample.
    P_diag : ndarray, shape (n, 6)
        Diagonal of the a-posteriori covariance.
    used : ndarray, shape (n, m), bool
        Anchors whose range entered the update.
    rejected : ndarray, shape (n, m), bool
        Anchors dropped by the innovation gate (finite range judged an outlier).
    reinit : ndarray, shape (n,), bool
        Samples at which the filter was (re-)initialised by trilateration.
    reflected : ndarray, shape (n,), bool
        Samples at which the state was reflected back to the physical side of a planar
        receiver array (see module notes).
    """

    x: np.ndarray
    P_diag: np.ndarray
    used: np.ndarray
    rejected: np.ndarray
    reinit: np.ndarray
    reflected: np.ndarray


def run_toa_ukf(t: np.ndarray, d: np.ndarray, anchors: np.ndarray, *,
                W_sigma: np.ndarray, V: np.ndarray, alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0, init_guess: np.ndarray | None = None,
                init_sigma_pos: float = 0.05, init_sigma_vel: float = 1.0,
                gate_sigma: float = 4.0, max_reject: int = 2, min_anchors: int = 3,
                reinit_after: int = 10, mirror_guard: bool = True) -> ToaUkfResult:
    """Track one transmitter from its ranges to fixed receivers with a UKF.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times (s), increasing.  ``Delta t_k = t_{k+1} - t_k`` (eq. 5).
    d : ndarray, shape (n, m)
        Measured ranges (m) to the ``m`` anchors; NaN where no echo arrived.
    anchors : ndarray, shape (m, 3)
        Receiver positions (m).
    W_sigma : array_like, shape (3,)
        Process-noise standard deviations ``sigma_wx, sigma_wy, sigma_wz`` (acceleration,
        m/s^2): ``W = diag(sigma^2)`` (eq. 4–5).
    V : array_like, shape (m,) or (m, m)
        Measurement-noise covariance (m^2): per-anchor variances ``e_j^2`` or a full matrix.
    alpha, beta, kappa : float
        Unscented-transform parameters (eq. 12–13).
    init_guess : array_like, shape (3,), optional
        Starting point of the trilateration that initialises the filter; it selects the
        side of a planar receiver array.  Default: the anchor centroid.
    init_sigma_pos, init_sigma_vel : float
        Standard deviations of the initial covariance (position m, velocity m/s).
    gate_sigma : float
        Innovation gate in predicted standard deviations; ``inf`` disables gating.
    max_reject : int
        Most anchors the gate may drop in one step; when more fail it, none is dropped.
    min_anchors : int
        Fewer usable anchors than this for ``reinit_after`` steps triggers a re-initialisation.
    reinit_after : int
    mirror_guard : bool
        Keep the state on the ``init_guess`` side of a planar array (module notes).

    Returns
    -------
    ToaUkfResult

    Notes
    -----
    Prediction (eq. 8, closed form for the linear model)::

        X_{k+1/k} = A X_{k/k},   P_{k+1/k} = A P_{k/k} A^T + G W G^T

    Update (eq. 9–11): sigma points ``chi = [X, X + B, X - B]`` with
    ``B = chol((n + lambda) P_{k+1/k})``, ``Y_i = h(chi_i)`` (eq. 6),
    ``Pyy = sum Wc (Y_i - Y)(Y_i - Y)^T + V``, ``Pxy = sum Wc (chi_i - X)(Y_i - Y)^T``,
    ``K = Pxy Pyy^-1``, ``X += K (d - Y)``, ``P -= K Pyy K^T``.
    """
    t = np.asarray(t, dtype=float)
    d = np.asarray(d, dtype=float)
    anchors = np.asarray(anchors, dtype=float)
    n_s, m = d.shape
    Wm, Wc, lam = ukf_weights(N_STATE, alpha, beta, kappa)
    Wq = np.diag(np.asarray(W_sigma, dtype=float) ** 2)
    V = np.asarray(V, dtype=float)
    Vm = np.diag(V) if V.ndim == 1 else V
    scale = N_STATE + lam
    guess = anchors.mean(axis=0) if init_guess is None else np.asarray(init_guess, float)
    P0 = np.diag([init_sigma_pos ** 2] * 3 + [init_sigma_vel ** 2] * 3)

    out_x = np.full((n_s, N_STATE), np.nan)
    out_p = np.full((n_s, N_STATE), np.nan)
    used = np.zeros((n_s, m), dtype=bool)
    rejected = np.zeros((n_s, m), dtype=bool)
    reinit = np.zeros(n_s, dtype=bool)
    reflected = np.zeros(n_s, dtype=bool)
    # planar array: the plane's normal pointing to the physical side (that of the guess)
    centre = anchors.mean(axis=0)
    _, sv, vt = np.linalg.svd(anchors - centre)
    normal = None
    if mirror_guard and m >= 3 and sv[-1] < 1e-3 * max(sv[0], 1e-12) \
            and init_guess is not None:
        normal = vt[-1] * np.sign(vt[-1] @ (guess - centre) or 1.0)

    # constant pieces of eq. (5): A = I + dt E,  G W G^T = dt^4/4 Q4 + dt^3/2 Q3 + dt^2 Q2
    E = np.zeros((N_STATE, N_STATE))
    E[0, 3] = E[1, 4] = E[2, 5] = 1.0
    I6 = np.eye(N_STATE)
    q = np.diag(Wq)
    Q4 = np.zeros((N_STATE, N_STATE))
    Q4[:3, :3] = np.diag(q)
    Q3 = np.zeros((N_STATE, N_STATE))
    Q3[:3, 3:] = Q3[3:, :3] = np.diag(q)
    Q2 = np.zeros((N_STATE, N_STATE))
    Q2[3:, 3:] = np.diag(q)
    # sigma-point offsets chi_i - X = S B^T with S = [0; I; -I] (eq. 7)
    S = np.vstack([np.zeros((1, N_STATE)), I6, -I6])
    Wc_col = Wc[:, None]
    gate2 = float(gate_sigma) ** 2
    use_gate = np.isfinite(gate_sigma)
    finite = np.isfinite(d)
    n_finite = finite.sum(axis=1)
    used[:] = finite

    x = None
    P = None
    starved = 0
    last_dt = None
    A = AT = Q = None
    for k in range(n_s):
        dk = d[k]
        if x is None or starved >= reinit_after:
            p0 = trilaterate(dk, anchors, guess)   # from the guess: its side of the array
            if not np.all(np.isfinite(p0)):
                if x is None:
                    used[k] = False
                    continue                       # wait for a sample with >= 3 ranges
            else:
                x = np.concatenate([p0, np.zeros(3)])
                P = P0.copy()
                reinit[k] = True
                starved = 0
                out_x[k] = x
                out_p[k] = P.diagonal()
                continue
        # -- a-priori statistics, eq. (8) (closed form of the unscented transform for A)
        dt = t[k] - t[k - 1]
        if dt != last_dt:
            A = I6 + dt * E
            AT = A.T
            Q = (0.25 * dt ** 4) * Q4 + (0.5 * dt ** 3) * Q3 + (dt * dt) * Q2  # G W G^T
            last_dt = dt
        x = A @ x                                                # X_{k+1/k} = A X_{k/k}
        P = A @ P @ AT + Q                                       # A P A^T + G W G^T
        n_ok = int(n_finite[k])
        if n_ok == 0:
            starved += 1
            out_x[k] = x
            out_p[k] = P.diagonal()
            continue
        # -- sigma points from the predicted covariance, eq. (9) with eq. (7)
        B, info = _potrf(scale * P, lower=1)
        if info != 0:
            P = 0.5 * (P + P.T) + 1e-12 * I6
            B, info = _potrf(scale * P, lower=1)
        dX = S @ B.T
        diff = (x[:3] + dX[:, :3])[:, None, :] - anchors
        Ysig = np.sqrt((diff * diff).sum(axis=2))                # Y_i = h(chi_i), eq. (6)
        ybar = Wm @ Ysig                                         # eq. (9)
        dY = Ysig - ybar
        WdY = Wc_col * dY
        Pyy = dY.T @ WdY + Vm                                    # eq. (10)
        Pxy = dX.T @ WdY                                         # eq. (10)
        nu = dk - ybar
        ok = None
        mismatch = False
        # -- per-anchor innovation gate (multipath), see module notes
        if use_gate and (nu * nu > gate2 * Pyy.diagonal()).any():
            z = np.abs(nu) / np.sqrt(Pyy.diagonal())
            z[~finite[k]] = 0.0
            bad = np.flatnonzero(z * z > gate2)
            if bad.size <= max_reject:        # else: the model, not multipath (keep all)
                rejected[k, bad] = True
                used[k, bad] = False
                n_ok -= bad.size
                ok = used[k]
            else:
                mismatch = True
                if n_ok < m:
                    ok = finite[k]
        elif n_ok < m:
            ok = finite[k]
        if n_ok == m:
            _, KT, info = _posv(Pyy, Pxy.T)                      # K = Pxy Pyy^-1, eq. (10)
            x = x + nu @ KT                                      # eq. (11)
            P = P - KT.T @ Pxy.T                                 # P - K Pyy K^T, eq. (11)
        elif n_ok > 0:
            s = np.flatnonzero(ok)
            Pxy_s = Pxy[:, s]
            _, KT, info = _posv(Pyy[np.ix_(s, s)], Pxy_s.T)
            x = x + nu[s] @ KT
            P = P - KT.T @ Pxy_s.T
        P += P.T
        P *= 0.5
        if normal is not None:
            h = normal @ (x[:3] - centre)
            if h < 0.0:                       # behind the receiver plane: the mirror image
                x = x.copy()
                x[:3] -= 2.0 * h * normal
                x[3:] -= 2.0 * (normal @ x[3:]) * normal
                reflected[k] = True
        starved = starved + 1 if (n_ok < min_anchors or mismatch) else 0
        p00 = P[0, 0]
        if p00 != p00 or abs(x[0]) > 1e3:                         # numerically lost
            starved = reinit_after
        out_x[k] = x
        out_p[k] = P.diagonal()
    return ToaUkfResult(x=out_x, P_diag=out_p, used=used, rejected=rejected, reinit=reinit,
                        reflected=reflected)
