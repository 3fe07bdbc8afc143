"""Kalman filters for one leg: state [x y ẋ ẏ] with an acceleration input (seed 000 §3.1, §5).

Three interchangeable implementations of the role ``filter``:

``kf`` (:class:`AxisKalmanFilter`)
    The filter of seed 000 written per axis.  With Q = diag(q, q), R = diag(r, r) and an
    initial covariance without x–y cross terms (all three hold in the paper), the 4×4
    covariance is block diagonal with two *identical* 2×2 blocks (position, velocity of one
    axis), so the whole filter is exact with three covariance numbers and scalar gains.
    This is the one the methods use: it is what makes a pure-Python tracker loop fast.
``kf_aniso`` (:class:`AnisotropicKalmanFilter`)
    The constant-velocity filter of seed 002 §II: a separate acceleration noise per axis
    (σ_ax = 1.63, σ_ay = 5.24 m/s²) and a separate measurement noise per axis (0.059 m in
    x, 0.02 m in y).  The axes stay uncoupled, so it is two 2×2 blocks, no longer equal.
``kf_matrix`` (:class:`MatrixKalmanFilter`)
    The textbook 4×4 matrix form of the same equations (either noise model), kept as the
    readable reference; the contract tests check every filter against it with the same
    noise matrices (:meth:`LegFilter.noise`).

A state is a tuple whose first four entries are the leg's ``x, y, vx, vy`` (sensor frame,
m and m/s) as Python floats; what follows is the filter's own (covariance terms for ``kf``
and ``kf_aniso``, the 4×4 array P for ``kf_matrix``).  The tracker and the other roles read
the first four entries and otherwise only call the methods below.

Notes
-----
seed000 eq. (1): x_k = A x_{k-1} + B_u u_{k-1} + B Δx_{k-1}, with
A = [[1,0,Δt,0],[0,1,0,Δt],[0,0,1,0],[0,0,0,1]], B_u = B = [[Δt²/2,0],[0,Δt²/2],[Δt,0],[0,Δt]].
seed000 eq. (2): y_k = C x_k + w_k, C = [[1,0,0,0],[0,1,0,0]].
seed000 eq. (7)–(8): prediction; the printed eq. (8) reads ``A P Aᵀ + Q B Qᵀ``, an evident
typo for the process noise of eq. (1), ``B Q Bᵀ``, which is what is implemented.
seed000 eq. (14)–(16): correction.  seed000 eq. (11)–(12): Mahalanobis distance and
innovation covariance.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np

from gaitval.registry import Registry
from gaitval.track.params import NO_SOURCE, declared, param

FILTERS = Registry("filter", table="gaitval.track.roles")


@dataclass(eq=False)
class LegFilter:
    """Role base: a filter for one leg's planar position and velocity (Q = diag(q², q²),
    R = diag(r², r²))."""

    q_accel_sd_mps2: float = param(15.0, "m/s²", "seed000 Table 2",
                                   "σ of the acceleration disturbance Δx")
    r_sd_m: float = param(0.04, "m", "seed000 Table 2", "observation noise σ")
    p0_pos_sd_m: float = param(0.04, "m", NO_SOURCE, "initial position uncertainty σ")
    p0_vel_sd_mps: float = param(0.5, "m/s", NO_SOURCE, "initial velocity uncertainty σ")

    def for_leg_width(self, leg_width_m: float) -> "LegFilter":
        """The filter for one subject: itself, or a copy whose measurement noise is set from
        the subject's leg width when ``r_sd_leg_widths`` is given (seed 001: R =
        diag((w_l/2)², (w_l/2)²), i.e. ``r_sd_leg_widths: 0.5``)."""
        k = getattr(self, "r_sd_leg_widths", None)
        if k is None:
            return self
        out = copy.copy(self)
        out.r_sd_m = k * leg_width_m
        out._noise_changed()
        return out

    def _noise_changed(self) -> None:
        """Recompute what a filter keeps derived from its noise parameters."""
        self._cache = {}

    def init(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0):
        raise NotImplementedError

    def predict(self, s, dt: float, ux: float, uy: float):
        """A priori state at k from the a posteriori state at k-1 (seed000 eq. (7)–(8))."""
        raise NotImplementedError

    def correct(self, s, zx: float, zy: float):
        """A posteriori state given the observation (zx, zy) (seed000 eq. (14)–(16))."""
        raise NotImplementedError

    def predict_pair(self, sl, sr, dt: float, ul, ur):
        """Both legs' a priori states, inputs ``ul``, ``ur`` = (ux, uy) (seed000 eq.
        (7)–(8)); one call per scan (filters override it with the arithmetic written out)."""
        predict = self.predict
        return predict(sl, dt, ul[0], ul[1]), predict(sr, dt, ur[0], ur[1])

    def gated_pair(self, pl, pr, obs, g: float):
        """:meth:`gated` of both legs: ``(left, right)`` lists of ``(j, λ²)``."""
        return self.gated(pl, obs, g), self.gated(pr, obs, g)

    def mahalanobis2(self, s, zx: float, zy: float) -> float:
        """λ² of seed000 eq. (11) for a predicted state ``s``."""
        raise NotImplementedError

    def lam2_all(self, s, obs) -> list[float]:
        """λ² of seed000 eq. (11) of every observation ``(zx, zy)`` in ``obs`` (one call per leg
        and scan; filters override it with a loop that hoists S out)."""
        m2 = self.mahalanobis2
        return [m2(s, zx, zy) for zx, zy in obs]

    def gated(self, s, obs, g: float) -> list[tuple[int, float]]:
        """``(j, λ²)`` (j = 1..J) of the observations with λ² < g (seed000 eq. (11), (13)):
        the χ² gate's work in one call per leg and scan."""
        return [(j, lam2) for j, lam2 in enumerate(self.lam2_all(s, obs), 1) if lam2 < g]

    def noise(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(Q_a, R, P0)``: acceleration-noise covariance (2×2, the Q of B Q Bᵀ), the
        measurement covariance (2×2) and the initial covariance (4×4) this filter uses."""
        return (np.eye(2) * self.q_accel_sd_mps2 ** 2, np.eye(2) * self.r_sd_m ** 2,
                np.diag([self.p0_pos_sd_m ** 2] * 2 + [self.p0_vel_sd_mps ** 2] * 2))

    def innovation_cov(self, s) -> np.ndarray:
        """S of seed000 eq. (12) as a 2×2 array."""
        raise NotImplementedError

    def pos(self, s) -> tuple[float, float]:
        return s[0], s[1]

    def vel(self, s) -> tuple[float, float]:
        return s[2], s[3]

    def posvel(self, s) -> tuple[float, float, float, float]:
        """(x, y, vx, vy) of a state."""
        return s[:4]



@declared
@dataclass(eq=False)
class AxisKalmanFilter(LegFilter):
    """Seed 000's Kalman filter, exact, per axis (see the module notes).

    State tuple ``(x, y, vx, vy, a, b, c)`` where ``[[a, b], [b, c]]`` is the covariance of
    (position, velocity) of either axis.
    """

    r_sd_leg_widths: float | None = param(
        None, "leg widths", "seed001 eq. (2)–(3) (0.5: R = diag((w_l/2)², (w_l/2)²))",
        "measurement noise σ in leg widths, set per subject (for_leg_width); None keeps "
        "r_sd_m")

    def __post_init__(self):
        self._noise_changed()

    def _noise_changed(self):
        self._cache: dict[float, tuple] = {}     # per Δt, see _consts
        self._r2 = self.r_sd_m ** 2               # r², the per-axis R

    def init(self, x, y, vx=0.0, vy=0.0):
        return (float(x), float(y), float(vx), float(vy),
                self.p0_pos_sd_m ** 2, 0.0, self.p0_vel_sd_mps ** 2)

    def _consts(self, dt):
        """(Δt²/2, q Δt⁴/4, q Δt³/2, q Δt²) for one Δt (cached: Δt rarely changes)."""
        h = 0.5 * dt * dt
        q = self.q_accel_sd_mps2 ** 2
        c = self._cache[dt] = (h, q * h * h, q * h * dt, q * dt * dt)
        return c

    def predict(self, s, dt, ux, uy):
        x, y, vx, vy, a, b, c = s
        cst = self._cache.get(dt)
        h, qaa, qab, qbb = cst if cst is not None else self._consts(dt)
        # seed000 eq. (7): x = A x + B_u u
        # seed000 eq. (8): P = A P Aᵀ + B Q Bᵀ
        #   (per axis: B Q Bᵀ = q [[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]])
        return (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux, vy + dt * uy,
                a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab, c + qbb)

    def predict_pair(self, sl, sr, dt, ul, ur):
        cst = self._cache.get(dt)
        h, qaa, qab, qbb = cst if cst is not None else self._consts(dt)
        x, y, vx, vy, a, b, c = sl
        ux, uy = ul
        # seed000 eq. (7)–(8) per leg, as predict
        pl = (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux, vy + dt * uy,
              a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab, c + qbb)
        x, y, vx, vy, a, b, c = sr
        ux, uy = ur
        return pl, (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux, vy + dt * uy,
                    a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab, c + qbb)

    def correct(self, s, zx, zy):
        x, y, vx, vy, a, b, c = s
        sv = a + self._r2            # seed000 eq. (12): S = C P Cᵀ + R (per axis)
        k0 = a / sv                          # seed000 eq. (15): K = P Cᵀ S⁻¹
        k1 = b / sv
        ex = zx - x
        ey = zy - y
        # seed000 eq. (14): x = x + K (y - C x)
        x = x + k0 * ex
        y = y + k0 * ey
        vx = vx + k1 * ex
        vy = vy + k1 * ey
        # seed000 eq. (16): P = (I - K C) P
        return (x, y, vx, vy, a - k0 * a, b - k0 * b, c - k1 * b)

    def mahalanobis2(self, s, zx, zy):
        ex = zx - s[0]
        ey = zy - s[1]
        return (ex * ex + ey * ey) / (s[4] + self._r2)   # seed000 eq. (11)

    def lam2_all(self, s, obs):
        px, py = s[0], s[1]
        sv = s[4] + self._r2                 # seed000 eq. (12), per axis
        out = []
        for zx, zy in obs:
            ex = zx - px
            ey = zy - py
            out.append((ex * ex + ey * ey) / sv)     # seed000 eq. (11)
        return out

    def gated(self, s, obs, g):
        px, py = s[0], s[1]
        sv = s[4] + self._r2                 # seed000 eq. (12), per axis
        lam2 = [((zx - px) * (zx - px) + (zy - py) * (zy - py)) / sv   # seed000 eq. (11)
                for zx, zy in obs]
        return [(j, v) for j, v in enumerate(lam2, 1) if v < g]        # seed000 eq. (13)

    def gated_pair(self, pl, pr, obs, g):
        lx, ly, rx, ry = pl[0], pl[1], pr[0], pr[1]
        svl, svr = pl[4] + self._r2, pr[4] + self._r2    # seed000 eq. (12), per axis
        cl, cr = [], []
        j = 0
        for zx, zy in obs:
            j += 1
            ex = zx - lx
            ey = zy - ly
            lam2 = (ex * ex + ey * ey) / svl         # seed000 eq. (11)
            if lam2 < g:                             # seed000 eq. (13)
                cl.append((j, lam2))
            ex = zx - rx
            ey = zy - ry
            lam2 = (ex * ex + ey * ey) / svr
            if lam2 < g:
                cr.append((j, lam2))
        return cl, cr

    def innovation_cov(self, s):
        v = s[4] + self._r2
        return np.array([[v, 0.0], [0.0, v]])




@declared
@dataclass(eq=False)
class AnisotropicKalmanFilter(LegFilter):
    """Constant-velocity Kalman filter with per-axis noise (seed 002 §II).

    Notes
    -----
    State tuple ``(x, y, vx, vy, ax, bx, cx, ay, by, cy)``: ``[[a, b], [b, c]]`` is the
    (position, velocity) covariance of each axis.  With Q = B diag(σ_ax², σ_ay²) Bᵀ and
    R = diag(r_x², r_y²) the two axes never couple, so the filter is exact per axis.
    Seed 002 gives the measurement noise as 0.059 m (x) and 0.02 m (y) without saying what
    they are; gaitval reads them as standard deviations.
    """

    q_accel_sd_mps2: tuple = param((1.63, 5.24), "m/s²", "seed002 §II",
                                   "σ_ax, σ_ay of the acceleration disturbance")
    r_sd_m: tuple = param((0.059, 0.02), "m", "seed002 §II (read as σ)",
                          "measurement noise σ in x and y")
    p0_pos_sd_m: float = param(0.05, "m", NO_SOURCE, "initial position uncertainty σ")

    def __post_init__(self):
        qx, qy = (float(v) for v in self.q_accel_sd_mps2)
        rx, ry = (float(v) for v in self.r_sd_m)
        self.q_accel_sd_mps2, self.r_sd_m = (qx, qy), (rx, ry)
        self._qx2, self._qy2 = qx * qx, qy * qy
        self._rx2, self._ry2 = rx * rx, ry * ry

    def init(self, x, y, vx=0.0, vy=0.0):
        a, c = self.p0_pos_sd_m ** 2, self.p0_vel_sd_mps ** 2
        return (float(x), float(y), float(vx), float(vy), a, 0.0, c, a, 0.0, c)

    def predict(self, s, dt, ux, uy):
        x, y, vx, vy, ax, bx, cx, ay, by, cy = s
        h = 0.5 * dt * dt
        qx, qy = self._qx2, self._qy2
        # seed000 eq. (7): x = A x + B u;  seed000 eq. (8) per axis with that axis' σ_a²
        # (seed 002 §II)
        return (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux, vy + dt * uy,
                ax + dt * (2.0 * bx + dt * cx) + qx * h * h, bx + dt * cx + qx * h * dt,
                cx + qx * dt * dt,
                ay + dt * (2.0 * by + dt * cy) + qy * h * h, by + dt * cy + qy * h * dt,
                cy + qy * dt * dt)

    def correct(self, s, zx, zy):
        x, y, vx, vy, ax, bx, cx, ay, by, cy = s
        sx = ax + self._rx2                  # S = C P Cᵀ + R, per axis
        sy = ay + self._ry2
        kx0, kx1 = ax / sx, bx / sx          # K = P Cᵀ S⁻¹
        ky0, ky1 = ay / sy, by / sy
        ex = zx - x
        ey = zy - y
        return (x + kx0 * ex, y + ky0 * ey, vx + kx1 * ex, vy + ky1 * ey,
                ax - kx0 * ax, bx - kx0 * bx, cx - kx1 * bx,          # P = (I − K C) P
                ay - ky0 * ay, by - ky0 * by, cy - ky1 * by)

    def mahalanobis2(self, s, zx, zy):
        ex = zx - s[0]
        ey = zy - s[1]
        return ex * ex / (s[4] + self._rx2) + ey * ey / (s[7] + self._ry2)

    def lam2_all(self, s, obs):
        px, py = s[0], s[1]
        sx, sy = s[4] + self._rx2, s[7] + self._ry2
        return [(zx - px) ** 2 / sx + (zy - py) ** 2 / sy for zx, zy in obs]

    def innovation_cov(self, s):
        return np.array([[s[4] + self._rx2, 0.0], [0.0, s[7] + self._ry2]])

    def noise(self):
        return (np.diag([self._qx2, self._qy2]), np.diag([self._rx2, self._ry2]),
                np.diag([self.p0_pos_sd_m ** 2] * 2 + [self.p0_vel_sd_mps ** 2] * 2))




class MatrixKalmanFilter(LegFilter):
    """The textbook 4×4 matrix form (reference implementation).

    Its parameters are :class:`LegFilter`'s; ``noise=(Q_a, R, P0)`` (as returned by
    :meth:`LegFilter.noise`) replaces the isotropic noise built from them, so any filter can
    be checked against it.
    """

    C = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])

    def __init__(self, noise=None, **params):
        super().__init__(**params)
        self._noise = (tuple(np.asarray(m, dtype=float) for m in noise) if noise is not None
                       else LegFilter.noise(self))

    def noise(self):
        return self._noise

    @staticmethod
    def _ab(dt):
        A = np.array([[1.0, 0, dt, 0], [0, 1.0, 0, dt], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])
        B = np.array([[dt * dt / 2, 0], [0, dt * dt / 2], [dt, 0], [0, dt]])
        return A, B

    @staticmethod
    def _state(x: np.ndarray, P: np.ndarray) -> tuple:
        return (*x.tolist(), P)

    def init(self, x, y, vx=0.0, vy=0.0):
        return self._state(np.array([x, y, vx, vy], dtype=float), self._noise[2].copy())

    def predict(self, s, dt, ux, uy):
        x, P = np.array(s[:4]), s[4]
        A, B = self._ab(dt)
        Q = self._noise[0]
        x = A @ x + B @ np.array([ux, uy])            # seed000 eq. (7)
        P = A @ P @ A.T + B @ Q @ B.T                  # seed000 eq. (8)
        return self._state(x, P)

    def innovation_cov(self, s):
        return self.C @ s[4] @ self.C.T + self._noise[1]   # seed000 eq. (12)

    def correct(self, s, zx, zy):
        x, P = np.array(s[:4]), s[4]
        S = self.innovation_cov(s)
        K = P @ self.C.T @ np.linalg.inv(S)            # seed000 eq. (15)
        x = x + K @ (np.array([zx, zy]) - self.C @ x)  # seed000 eq. (14)
        P = (np.eye(4) - K @ self.C) @ P               # seed000 eq. (16)
        return self._state(x, P)

    def mahalanobis2(self, s, zx, zy):
        e = np.array([zx - s[0], zy - s[1]])
        return float(e @ np.linalg.solve(self.innovation_cov(s), e))   # seed000 eq. (11)

