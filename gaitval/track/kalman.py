"""Kalman filters for one leg: state [x y ẋ ẏ] with an acceleration input (seed 000 §3.1, §5).

Two interchangeable implementations of the role ``filter``:

``kf`` (:class:`AxisKalmanFilter`)
    The filter of seed 000 written per axis.  With Q = diag(q, q), R = diag(r, r) and an
    initial covariance without x–y cross terms (all three hold in the paper), the 4×4
    covariance is block diagonal with two *identical* 2×2 blocks (position, velocity of one
    axis), so the whole filter is exact with three covariance numbers and scalar gains.
    This is the one the methods use: it is what makes a pure-Python tracker loop fast.
``kf_matrix`` (:class:`MatrixKalmanFilter`)
    The textbook 4×4 matrix form of the same equations, kept as the readable reference;
    the contract tests check that both give the same numbers.

A state is an opaque value owned by the filter (a tuple for ``kf``, ``(x, P)`` arrays for
``kf_matrix``); the tracker only calls the methods below.

Notes
-----
Seed 000 eq. (1): x_k = A x_{k-1} + B_u u_{k-1} + B Δx_{k-1}, with
A = [[1,0,Δt,0],[0,1,0,Δt],[0,0,1,0],[0,0,0,1]], B_u = B = [[Δt²/2,0],[0,Δt²/2],[Δt,0],[0,Δt]].
Eq. (2): y_k = C x_k + w_k, C = [[1,0,0,0],[0,1,0,0]].
Eq. (7)–(8): prediction; the printed eq. (8) reads ``A P Aᵀ + Q B Qᵀ``, an evident typo for
the process noise of eq. (1), ``B Q Bᵀ``, which is what is implemented.
Eq. (14)–(16): correction.  Eq. (11)–(12): Mahalanobis distance and innovation covariance.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import numpy as np

from gaitval.registry import Registry

FILTERS = Registry("filter")


class LegFilter:
    """Role base: a filter for one leg's planar position and velocity.

    Parameters
    ----------
    q_accel_sd_mps2 : float
        Standard deviation of the acceleration disturbance Δx (Q = diag(q², q²)); seed 000
        Table 2: 15.0.
    r_sd_m : float
        Observation noise standard deviation (R = diag(r², r²)); seed 000 Table 2: 0.04.
    p0_pos_sd_m, p0_vel_sd_mps : float
        Initial state uncertainty (not given in the paper).
    """

    def __init__(self, q_accel_sd_mps2: float = 15.0, r_sd_m: float = 0.04,
                 p0_pos_sd_m: float = 0.04, p0_vel_sd_mps: float = 0.5):
        self.q_accel_sd_mps2 = q_accel_sd_mps2
        self.r_sd_m = r_sd_m
        self.p0_pos_sd_m = p0_pos_sd_m
        self.p0_vel_sd_mps = p0_vel_sd_mps

    def init(self, x: float, y: float, vx: float = 0.0, vy: float = 0.0):
        raise NotImplementedError

    def predict(self, s, dt: float, ux: float, uy: float):
        """A priori state at k from the a posteriori state at k-1 (eq. 7–8)."""
        raise NotImplementedError

    def correct(self, s, zx: float, zy: float):
        """A posteriori state given the observation (zx, zy) (eq. 14–16)."""
        raise NotImplementedError

    def mahalanobis2(self, s, zx: float, zy: float) -> float:
        """λ² of eq. (11) for a predicted state ``s``."""
        raise NotImplementedError

    def innovation_cov(self, s) -> np.ndarray:
        """S of eq. (12) as a 2×2 array."""
        raise NotImplementedError

    def pos(self, s) -> tuple[float, float]:
        raise NotImplementedError

    def vel(self, s) -> tuple[float, float]:
        raise NotImplementedError

    def posvel(self, s) -> tuple[float, float, float, float]:
        """(x, y, vx, vy) of a state."""
        return self.pos(s) + self.vel(s)

    def with_state(self, s, x: float, y: float, vx: float, vy: float):
        """``s`` with its mean replaced (covariance kept); used to rewrite a history."""
        raise NotImplementedError


@FILTERS.register("kf")
class AxisKalmanFilter(LegFilter):
    """Seed 000's Kalman filter, exact, per axis (see the module notes).

    State tuple ``(x, y, vx, vy, a, b, c)`` where ``[[a, b], [b, c]]`` is the covariance of
    (position, velocity) of either axis.
    """

    def init(self, x, y, vx=0.0, vy=0.0):
        return (float(x), float(y), float(vx), float(vy),
                self.p0_pos_sd_m ** 2, 0.0, self.p0_vel_sd_mps ** 2)

    def _consts(self, dt):
        """(Δt²/2, q Δt⁴/4, q Δt³/2, q Δt²) for one Δt (cached: Δt rarely changes)."""
        key = (dt, self.q_accel_sd_mps2)
        if getattr(self, "_ckey", None) != key:
            h = 0.5 * dt * dt
            q = self.q_accel_sd_mps2 ** 2
            self._ckey, self._cval = key, (h, q * h * h, q * h * dt, q * dt * dt)
        return self._cval

    def predict(self, s, dt, ux, uy):
        x, y, vx, vy, a, b, c = s
        h, qaa, qab, qbb = self._consts(dt)
        # eq. (7): x = A x + B_u u
        # eq. (8): P = A P Aᵀ + B Q Bᵀ (per axis: B Q Bᵀ = q [[Δt⁴/4, Δt³/2], [Δt³/2, Δt²]])
        return (x + dt * vx + h * ux, y + dt * vy + h * uy, vx + dt * ux, vy + dt * uy,
                a + dt * (2.0 * b + dt * c) + qaa, b + dt * c + qab, c + qbb)

    def correct(self, s, zx, zy):
        x, y, vx, vy, a, b, c = s
        sv = a + self.r_sd_m ** 2            # eq. (12): S = C P Cᵀ + R (per axis)
        k0 = a / sv                          # eq. (15): K = P Cᵀ S⁻¹
        k1 = b / sv
        ex = zx - x
        ey = zy - y
        # eq. (14): x = x + K (y - C x)
        x = x + k0 * ex
        y = y + k0 * ey
        vx = vx + k1 * ex
        vy = vy + k1 * ey
        # eq. (16): P = (I - K C) P
        return (x, y, vx, vy, a - k0 * a, b - k0 * b, c - k1 * b)

    def mahalanobis2(self, s, zx, zy):
        ex = zx - s[0]
        ey = zy - s[1]
        return (ex * ex + ey * ey) / (s[4] + self.r_sd_m ** 2)   # eq. (11)

    def innovation_cov(self, s):
        v = s[4] + self.r_sd_m ** 2
        return np.array([[v, 0.0], [0.0, v]])

    def pos(self, s):
        return s[0], s[1]

    def vel(self, s):
        return s[2], s[3]

    def posvel(self, s):
        return s[:4]

    def with_state(self, s, x, y, vx, vy):
        return (float(x), float(y), float(vx), float(vy), s[4], s[5], s[6])


@FILTERS.register("kf_matrix")
class MatrixKalmanFilter(LegFilter):
    """The same filter in full 4×4 matrix form (reference implementation)."""

    C = np.array([[1.0, 0, 0, 0], [0, 1.0, 0, 0]])

    @staticmethod
    def _ab(dt):
        A = np.array([[1.0, 0, dt, 0], [0, 1.0, 0, dt], [0, 0, 1.0, 0], [0, 0, 0, 1.0]])
        B = np.array([[dt * dt / 2, 0], [0, dt * dt / 2], [dt, 0], [0, dt]])
        return A, B

    def init(self, x, y, vx=0.0, vy=0.0):
        P = np.diag([self.p0_pos_sd_m ** 2] * 2 + [self.p0_vel_sd_mps ** 2] * 2)
        return (np.array([x, y, vx, vy], dtype=float), P)

    def predict(self, s, dt, ux, uy):
        x, P = s
        A, B = self._ab(dt)
        Q = np.eye(2) * self.q_accel_sd_mps2 ** 2
        x = A @ x + B @ np.array([ux, uy])            # eq. (7)
        P = A @ P @ A.T + B @ Q @ B.T                  # eq. (8)
        return (x, P)

    def innovation_cov(self, s):
        R = np.eye(2) * self.r_sd_m ** 2
        return self.C @ s[1] @ self.C.T + R            # eq. (12)

    def correct(self, s, zx, zy):
        x, P = s
        S = self.innovation_cov(s)
        K = P @ self.C.T @ np.linalg.inv(S)            # eq. (15)
        x = x + K @ (np.array([zx, zy]) - self.C @ x)  # eq. (14)
        P = (np.eye(4) - K @ self.C) @ P               # eq. (16)
        return (x, P)

    def mahalanobis2(self, s, zx, zy):
        e = np.array([zx, zy]) - self.C @ s[0]
        return float(e @ np.linalg.solve(self.innovation_cov(s), e))   # eq. (11)

    def pos(self, s):
        return float(s[0][0]), float(s[0][1])

    def vel(self, s):
        return float(s[0][2]), float(s[0][3])

    def with_state(self, s, x, y, vx, vy):
        return (np.array([x, y, vx, vy], dtype=float), s[1].copy())
