"""Unscented Kalman filter for time-of-arrival (TOA) ranging: constant-velocity model.

The filter follows seed 003 §3.2 line by line: state ``[x y z vx vy vz]`` (eq. 3), linear
constant-velocity transition with acceleration noise (eq. 4–5), range measurement to each
receiver (anchor) (eq. 6), scaled sigma points (eq. 7, 12, 13), a-priori statistics (eq. 8),
measurement sigma points drawn again from the predicted covariance (eq. 9), gain (eq. 10)
and a-posteriori statistics (eq. 11).  :class:`ToaUkf` is the filter as a tracker role
(``toa_ukf`` in :data:`UKF_TRACKERS`), built from config ``ultrasonic.ukf``; its
:meth:`ToaUkf.track` turns one ultrasonic log into a track table.

What the paper leaves open is made explicit here:

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
  the receivers) and a state that ends a sample on the other side (after an update, or coasting on
  its prediction alone) is reflected back
  (position and velocity); this is counted in ``reflected``.
* **Checked (re-)initialisation.**  The paper's filter starts from a known position;
  gaitval starts (and restarts a lost filter) from a trilateration of one sample's ranges.
  A late echo in that sample makes the ranges inconsistent, and an unchecked Gauss–Newton
  can land anywhere (issue 34: 490 km from the board at sample 0 of a simulated trial).
  :func:`trilaterate_checked` accepts a fix only when its range residual is small, it lies
  within the sensor's range (20 m, §5), and, failing that with all anchors, tries the
  subsets that leave one anchor out; no fix means the filter waits for the next sample.
* **The a-priori step for a linear model.**  Passing sigma points through the linear
  transition ``A`` (eq. 8) gives exactly ``A P A^T`` (the unscented transform is exact for
  linear maps), so eq. (8) is evaluated in that closed form, which is cheaper and free of
  the round-off of the large negative weight ``W_0`` that ``alpha = 1e-3`` produces.

The per-sample cycle (predict, sigma points, gate, update, reflect) runs compiled
(:mod:`gaitval.track.ukf_kernel`, numba, the numpy formulation's array expressions).
``alpha = 1e-3`` gives ``W_0 ≈ -10^6`` (eq. 12), which amplifies round-off, so a track's
last digits depend on the BLAS build and the CPU; on one machine the numbers are the same
every run (docs/numerics.md).

References
----------
Qi, Y.; Soh, C.B.; Gunawan, E.; Low, K.-S.; Thomas, R. Estimation of Spatial-Temporal Gait
Parameters Using a Low-Cost Ultrasonic Motion Analysis System. *Sensors* 2014, 14,
15434–15457. doi:10.3390/s140815434
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError, TimestampError
from gaitval.io.ultrasonic import anchor_positions, log_distances
from gaitval.registry import Registry
from gaitval.types import UltrasonicLog

N_STATE = 6
#: Columns of a track (:meth:`ToaUkf.track`).
TRACK_COLUMNS = ["t_s", "x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps",
                 "used_anchors", "rejected_anchors"]
#: Trackers of one transmitter from its ranges (seed 003); config ``ultrasonic.ukf``.
UKF_TRACKERS = Registry("ultrasonic tracker", table="gaitval.track.roles")


def ukf_weights(n: int = N_STATE, alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0) -> tuple[np.ndarray, np.ndarray, float]:
    """Sigma-point weights of the scaled unscented transform.

    ``n`` is the state dimension; ``alpha, beta, kappa`` the spread, prior-distribution and
    secondary scaling parameters (seed 003 uses ``1e-3``, ``2``, ``0``).  Returns ``Wm``,
    ``Wc`` (shape (2n+1,): weights of the mean and of the covariance) and ``lambda``:
    ``lambda = alpha^2 (n + kappa) - n`` (eq. 13);
    ``W0m = lambda/(n+lambda)``, ``W0c = lambda/(n+lambda) + 1 - alpha^2 + beta``,
    ``Wim = Wic = 1/(2(n+lambda))`` (eq. 12).
    """
    lam = alpha ** 2 * (n + kappa) - n               # seed003 eq. (13)
    Wm = np.full(2 * n + 1, 1.0 / (2.0 * (n + lam)))  # seed003 eq. (12)
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
    fewer than three ranges are finite.  No check of the result: ranges that no point fits
    (a late echo) can send the iteration anywhere; :func:`trilaterate_checked` is the one
    the filter uses.
    """
    ok = np.isfinite(d)
    if ok.sum() < 3:
        return np.full(3, np.nan)
    a, r = anchors[ok], d[ok]
    p = np.asarray(guess, dtype=float).copy()
    with np.errstate(over="ignore", invalid="ignore"):
        for _ in range(n_iter):
            diff = p - a
            rng = np.linalg.norm(diff, axis=1)
            J = diff / np.maximum(rng, 1e-9)[:, None]
            if not np.all(np.isfinite(J)):
                return np.full(3, np.nan)           # diverged (inconsistent ranges)
            step, *_ = np.linalg.lstsq(J, r - rng, rcond=None)
            p = p + step
            if np.linalg.norm(step) < 1e-10:
                break
    return p


@dataclass(frozen=True)
class Fix:
    """What :func:`trilaterate_checked` returns.

    ``p`` (3,): the position, NaN when refused; ``used`` (m,): the anchors of the fix;
    ``residual_m``: RMS of measured minus fitted range over ``used`` (NaN when refused);
    ``reason``: ``""`` for a fix, else why it was refused (``"fewer than 3 ranges"``,
    ``"no consistent anchor set"``, ``"ambiguous"``).
    """

    p: np.ndarray
    used: np.ndarray
    residual_m: float
    reason: str = ""


def trilaterate_checked(d: np.ndarray, anchors: np.ndarray, guess: np.ndarray, *,
                        max_residual_m: float = 0.05, max_range_m: float = 20.0) -> Fix:
    """A position from ranges that the ranges support, or none (issue 34).

    1. Ranges beyond ``max_range_m`` (the sensor's range, seed 003 §5: 20 m) or not finite
       are not used.
    2. All usable ranges are fitted (:func:`trilaterate`, from ``guess``).  The fix is
       accepted when the RMS residual (measured − fitted range) is at most
       ``max_residual_m`` and the point lies within ``max_range_m`` of the anchor centroid.
    3. Otherwise, with four or more usable ranges, every subset that leaves one anchor
       out is fitted.  A subset's fix is a candidate when it passes the same two checks
       and the anchor left out is not *early*: a reflected path is longer than the direct
       one, so a left-out range may exceed its fitted range (a late echo) but not fall
       short of it by more than ``max_residual_m``.  One candidate, or several within
       ``max_residual_m`` of each other, give the fix (the smallest residual); candidates
       that disagree leave the sample without a fix (``"ambiguous"``).

    The same checks run at every (re)initialisation of :func:`run_toa_ukf`.  Seed 003
    gives no initialisation (its UKF starts from a known position); the rule is gaitval's.
    """
    d = np.asarray(d, dtype=float)
    anchors = np.asarray(anchors, dtype=float)
    centre = anchors.mean(axis=0)
    ok = np.isfinite(d) & (d <= max_range_m)
    none = np.zeros(len(d), dtype=bool)
    if ok.sum() < 3:
        return Fix(np.full(3, np.nan), none, float("nan"), "fewer than 3 ranges")

    def fit(use: np.ndarray):
        p = trilaterate(np.where(use, d, np.nan), anchors, guess)
        if not np.all(np.isfinite(p)) or np.linalg.norm(p - centre) > max_range_m:
            return None
        res = d - np.linalg.norm(anchors - p, axis=1)
        rms = float(np.sqrt(np.mean(res[use] ** 2)))
        return (p, rms, res) if rms <= max_residual_m else None

    full = fit(ok)
    if full is not None:
        return Fix(full[0], ok.copy(), full[1])
    cands = []
    if ok.sum() >= 4:
        for j in np.flatnonzero(ok):
            use = ok.copy()
            use[j] = False
            f = fit(use)
            if f is not None and f[2][j] >= -max_residual_m:   # left out: late, not early
                cands.append((f[1], int(j), f[0], use))
    if not cands:
        return Fix(np.full(3, np.nan), none, float("nan"), "no consistent anchor set")
    pts = np.array([c[2] for c in cands])
    if np.max(np.linalg.norm(pts[:, None] - pts[None], axis=2)) > max_residual_m:
        return Fix(np.full(3, np.nan), none, float("nan"), "ambiguous")
    rms, _, p, use = min(cands, key=lambda c: (c[0], c[1]))
    return Fix(p, use, rms)


@dataclass
class ToaUkfResult:
    """What :func:`run_toa_ukf` returns (arrays aligned with the input samples).

    ``x`` (n, 6): a-posteriori state ``[x y z vx vy vz]`` (metres, m/s); ``P_diag`` (n, 6):
    diagonal of the a-posteriori covariance; ``used`` (n, m): anchors whose range entered
    the update; ``rejected`` (n, m): anchors dropped by the innovation gate (finite range
    judged an outlier); ``reinit`` (n,): samples at which the filter was (re-)initialised
    by trilateration; ``reflected`` (n,): samples at which the state was reflected back to
    the physical side of a planar receiver array (module notes); ``refused`` (n,): samples
    at which a (re-)initialisation was due but :func:`trilaterate_checked` gave no fix.
    """

    x: np.ndarray
    P_diag: np.ndarray
    used: np.ndarray
    rejected: np.ndarray
    reinit: np.ndarray
    reflected: np.ndarray
    refused: np.ndarray

    @classmethod
    def start(cls, finite: np.ndarray) -> "ToaUkfResult":
        """Before the first sample: no state, every finite range counted as used."""
        n, m = finite.shape
        return cls(x=np.full((n, N_STATE), np.nan), P_diag=np.full((n, N_STATE), np.nan),
                   used=finite.copy(), rejected=np.zeros((n, m), dtype=bool),
                   reinit=np.zeros(n, dtype=bool), reflected=np.zeros(n, dtype=bool),
                   refused=np.zeros(n, dtype=bool))


def run_toa_ukf(t: np.ndarray, d: np.ndarray, anchors: np.ndarray, *,
                W_sigma: np.ndarray, V: np.ndarray, alpha: float = 1e-3, beta: float = 2.0,
                kappa: float = 0.0, init_guess: np.ndarray | None = None,
                init_sigma_pos: float = 0.05, init_sigma_vel: float = 1.0,
                gate_sigma: float = 4.0, max_reject: int = 2, min_anchors: int = 3,
                reinit_after: int = 10, mirror_guard: bool = True,
                init_max_residual_m: float = 0.05, max_range_m: float = 20.0) -> ToaUkfResult:
    """Track one transmitter from its ranges to fixed receivers with a UKF.

    Parameters
    ----------
    t, d, anchors : ndarray, shapes (n,), (n, m), (m, 3)
        Sample times (s, increasing; ``Delta t_k = t_{k+1} - t_k``, eq. 5), measured
        ranges (m) to the ``m`` anchors (NaN where no echo arrived), anchor positions (m).
    W_sigma : array_like, shape (3,)
        Process-noise sds per axis (acceleration, m/s^2): ``W = diag(sigma^2)`` (eq. 4–5).
    V : array_like, shape (m,) or (m, m)
        Measurement-noise covariance (m^2): per-anchor variances ``e_j^2`` or a full matrix.
    alpha, beta, kappa : float
        Unscented-transform parameters (eq. 12–13).
    init_guess : array_like, shape (3,), optional
        Start of the trilateration that initialises the filter; it selects the side of a
        planar receiver array.  Default: the anchor centroid.
    init_sigma_pos, init_sigma_vel : float
        Standard deviations of the initial covariance (position m, velocity m/s).
    gate_sigma, max_reject : float, int
        Innovation gate in predicted sds (``inf``: no gating) and the most anchors it may
        drop in one step (when more fail it, none is dropped).
    min_anchors, reinit_after : int
        Fewer usable anchors than ``min_anchors`` for ``reinit_after`` steps re-initialises.
    mirror_guard : bool
        Keep the state on the ``init_guess`` side of a planar array (module notes).
    init_max_residual_m, max_range_m : float
        Checks of every (re-)initialisation (:func:`trilaterate_checked`): the largest RMS
        range residual of a fix and the sensor's range (seed 003 §5: 20 m).

    Returns
    -------
    ToaUkfResult

    Notes
    -----
    Per sample (:func:`_filter`): (re-)initialise by a checked trilateration when needed,
    predict (eq. 8, closed form), update from the anchors that pass the gate (eq. 9–11),
    reflect a mirror state back.
    """
    t = np.ascontiguousarray(t, dtype=float)
    d = np.ascontiguousarray(d, dtype=float)
    anchors = np.ascontiguousarray(anchors, dtype=float)
    guess = anchors.mean(axis=0) if init_guess is None else np.asarray(init_guess, float)
    normal, centre = _mirror_plane(anchors, guess, mirror_guard and init_guess is not None)
    model = _model(anchors, W_sigma, V, alpha, beta, kappa, gate_sigma, max_reject,
                   min_anchors, reinit_after, normal, centre)
    P0 = np.diag([init_sigma_pos ** 2] * 3 + [init_sigma_vel ** 2] * 3)
    res = ToaUkfResult.start(np.isfinite(d))
    _filter(t, d, model, P0, res,
            lambda dk: trilaterate_checked(dk, anchors, guess,
                                           max_residual_m=init_max_residual_m,
                                           max_range_m=max_range_m))
    return res


def _filter(t, d, model, P0, res: ToaUkfResult, fix_of) -> None:
    """The per-sample loop of :func:`run_toa_ukf` into ``res``: a checked fix
    (``fix_of(d_k)``, :func:`trilaterate_checked`) where the filter has no state or has
    starved, and :func:`gaitval.track.ukf_kernel.ukf_steps` (predict, update, reflect)
    from there until it starves."""
    from gaitval.track.ukf_kernel import ukf_steps   # numba: only a UKF job pays it

    n_s = len(d)
    n_finite = np.isfinite(d).sum(axis=1).astype(np.int64)
    out = (res.x, res.P_diag, res.used, res.rejected, res.reflected)
    x = P = None
    starved = np.zeros(1, dtype=np.int64)
    k = 0
    while k < n_s:
        # here the filter has no state yet, or has starved for reinit_after samples
        # from the guess: its side of the array; a fix the ranges do not support is refused
        fix = fix_of(d[k])
        force = False
        if np.all(np.isfinite(fix.p)):
            res.used[k] = fix.used                  # the anchors of the fix
            x, P, starved[0] = np.concatenate([fix.p, np.zeros(3)]), P0.copy(), 0
            res.reinit[k] = True
            res.x[k], res.P_diag[k] = x, P0.diagonal()
            k += 1
        else:
            res.refused[k] = n_finite[k] >= 3       # ranges there, but no consistent fix
            if x is None:
                res.used[k] = False
                k += 1                              # wait for a sample with >= 3 ranges
                continue
            force = True                            # still lost: predict and update anyway
        if k < n_s:
            # per sample: predict (eq. 8), update (eq. 9-11), reflect (module notes)
            k, P = ukf_steps(k, force, t, d, n_finite, model, x, P, starved, out)


def _model(anchors, W_sigma, V, alpha, beta, kappa, gate_sigma, max_reject, min_anchors,
           reinit_after, normal, centre) -> tuple:
    """The constants of one run as :func:`gaitval.track.ukf_kernel.ukf_steps` takes them:
    weights (eq. 12–13), ``n + lambda`` of eq. (7), V, W's diagonal (eq. 4–5), the gate,
    the re-initialisation rule and the receiver plane (``normal`` empty: none)."""
    Wm, Wc, lam = ukf_weights(N_STATE, alpha, beta, kappa)
    V = np.asarray(V, dtype=float)
    V = np.ascontiguousarray(np.diag(V) if V.ndim == 1 else V)
    q = np.asarray(W_sigma, dtype=float) ** 2
    return (anchors, Wm, Wc, float(N_STATE + lam), V, q, float(gate_sigma) ** 2,
            bool(np.isfinite(gate_sigma)), int(max_reject), int(min_anchors),
            int(reinit_after), np.zeros(0) if normal is None else normal, centre)


def _mirror_plane(anchors: np.ndarray, guess: np.ndarray, guard: bool):
    """Normal of a planar array pointing to the physical side (the guess's), or None."""
    centre = anchors.mean(axis=0)
    _, sv, vt = np.linalg.svd(anchors - centre)
    if guard and len(anchors) >= 3 and sv[-1] < 1e-3 * max(sv[0], 1e-12):
        return vt[-1] * np.sign(vt[-1] @ (guess - centre) or 1.0), centre
    return None, centre


def warm_up() -> None:
    """Compile the UKF kernel (:func:`gaitval.track.ukf_kernel.ukf_steps`), or load it from
    numba's cache, on a tiny problem: a transmitter in front of four coplanar receivers,
    one range missing.

    Called where :func:`gaitval.track.pf.warm_up` is (a stage verb before its pool forks
    its workers, :func:`gaitval.jobs.stages.preload`; ``run.py`` after installing), with
    the argument types of :meth:`ToaUkf.track`, so a track afterwards finds its specialisation (tests/test_ukf.py checks it adds none).
    """
    anchors = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.2, 0.0], [0.3, 0.2, 0.0]])
    t = np.arange(12) / 100.0
    pos = np.column_stack([0.1 + 0.5 * t, np.full(12, 0.1), np.full(12, -0.3)])
    d = toa_ranges(pos, anchors)
    d[5, 1] = np.nan
    run_toa_ukf(t, d, anchors, W_sigma=np.array([30.0, 25.0, 10.0]), V=np.full(4, 1e-5),
                init_guess=np.array([0.16, 0.10, -0.30]), max_reject=2, min_anchors=3,
                reinit_after=10)


@dataclass
class ToaUkf:
    """The UKF of seed 003 as a tracker role, with the parameters of :func:`run_toa_ukf`
    under their config names (``ultrasonic.ukf``): ``W_sigma_mps2`` (W_sigma, m/s^2),
    ``V_m2`` (V, m^2 per anchor), ``init_guess_m``, ``init_sigma_pos_m``,
    ``init_sigma_vel_mps``; the others keep their names.

    Defaults: seed 003 §3.2 and §4.3.  §4.3.1 gives W as 30, 25, 10 "mm/s"; with G of
    eq. (5) w is an acceleration, and a heel needs tens of m/s^2, so the numbers are read
    as m/s^2.  V is §4.3.2's diag(11, 9.3, 9, 9) mm^2.  ``max_range_m`` is §5's maximum
    propagation distance (20 m); ``init_max_residual_m`` is gaitval's (issue 34,
    :func:`trilaterate_checked`): 0.05 m, about 15 times the ~3 mm range noise of §4.3.2,
    so noise alone never refuses a fix, and chosen before looking at any track.
    """

    alpha: float = 1e-3
    beta: float = 2.0
    kappa: float = 0.0
    W_sigma_mps2: list = field(default_factory=lambda: [30.0, 25.0, 10.0])
    V_m2: list = field(default_factory=lambda: [11e-6, 9.3e-6, 9e-6, 9e-6])
    gate_sigma: float = 4.0
    max_reject: int = 2
    min_anchors: int = 3
    reinit_after: int = 10
    init_guess_m: list = field(default_factory=lambda: [0.16, 0.10, -0.30])
    init_sigma_pos_m: float = 0.05
    init_sigma_vel_mps: float = 1.0
    init_max_residual_m: float = 0.05
    max_range_m: float = 20.0
    mirror_guard: bool = True

    def track(self, log: UltrasonicLog, *, trial: str | None = None) -> pd.DataFrame:
        """Track the transmitter of one ultrasonic log (seed 003 §3.2).

        Returns a DataFrame with one row per log sample, columns :data:`TRACK_COLUMNS`:
        ``t_s`` (ultrasonic clock), ``x_m, y_m, z_m`` (ultrasonic frame), ``vx_mps, vy_mps,
        vz_mps``, ``used_anchors`` (ranges that entered the update), ``rejected_anchors``
        (finite ranges the multipath gate dropped); ``attrs``: ``anchors`` (the anchor
        table, records), ``n_reinit``, ``n_reflected``, ``n_init_refused`` (samples where a
        (re-)initialisation found no fix the ranges support).
        """
        t = np.asarray(log.t, dtype=float)
        if t.size < 2 or np.any(np.diff(t) <= 0):
            raise TimestampError("ultrasonic sample times must increase strictly",
                                 path=log.source or None, trial=trial,
                                 hint="see the log's timestamp issues (gaitval inspect)")
        d = log_distances(log)
        anchors = anchor_positions(log.anchors)
        V = np.asarray(self.V_m2, dtype=float)
        if V.shape[0] != anchors.shape[0]:
            raise ConfigError(f"ultrasonic.ukf.V_m2 has {V.shape[0]} entries but the log "
                              f"has {anchors.shape[0]} anchors", path=log.source or None,
                              trial=trial)
        r = run_toa_ukf(
            t, d, anchors, W_sigma=np.asarray(self.W_sigma_mps2, float), V=V,
            alpha=self.alpha, beta=self.beta, kappa=self.kappa,
            init_guess=np.asarray(self.init_guess_m, float),
            init_sigma_pos=self.init_sigma_pos_m, init_sigma_vel=self.init_sigma_vel_mps,
            gate_sigma=self.gate_sigma, max_reject=int(self.max_reject),
            min_anchors=int(self.min_anchors), reinit_after=int(self.reinit_after),
            mirror_guard=self.mirror_guard,
            init_max_residual_m=float(self.init_max_residual_m),
            max_range_m=float(self.max_range_m))
        df = pd.DataFrame({"t_s": t, "x_m": r.x[:, 0], "y_m": r.x[:, 1], "z_m": r.x[:, 2],
                           "vx_mps": r.x[:, 3], "vy_mps": r.x[:, 4], "vz_mps": r.x[:, 5],
                           "used_anchors": r.used.sum(axis=1).astype(np.int64),
                           "rejected_anchors": r.rejected.sum(axis=1).astype(np.int64)})
        df.attrs["anchors"] = log.anchors.to_dict("records")
        df.attrs["n_reinit"] = int(r.reinit.sum())
        df.attrs["n_reflected"] = int(r.reflected.sum())
        df.attrs["n_init_refused"] = int(r.refused.sum())
        return df

