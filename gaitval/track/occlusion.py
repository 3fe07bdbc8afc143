"""Occlusion handlers: what a tracker does about a leg that was hidden (UO) for a while.

Role ``occlusion``: ``delay(n_uo)`` says how many steps after the leg reappears the
handler wants to act (``None``: never), and ``virtual_observations(p0, p1, p2, p3, n_uo)``
returns the observations to re-filter the hidden steps with.  ``n_before(n_uo)`` /
``n_after(n_uo)`` give N_bo / N_ao, where the outer control points are taken.

Notes
-----
Seed 000 eq. (17), Catmull–Rom: with the leg observed at k and at k+N_uo+1 and hidden in
between, the virtual observations are

    y'_{k+i} = ½ [1 τ τ² τ³] M [y_{k−N_bo}; y_k; y_{k+N_uo+1}; y_{k+N_uo+N_ao+1}],
    M = [[0, 2, 0, 0], [−1, 0, 1, 0], [2, −5, 4, −1], [−1, 3, −3, 1]],
    τ = i/(N_uo + 1), i = 1..N_uo,

and the Kalman filter is run again from step k with them (§5.4).

N_bo and N_ao are not given in the paper.  Eq. (17) is the *uniform* Catmull–Rom spline:
its end tangents, (y_{k+N_uo+1} − y_{k−N_bo})/2 per unit τ, equal the leg's velocity only
when the control points are spaced like the interpolated interval, i.e. N_bo = N_ao =
N_uo + 1 steps.  gaitval's default is therefore ``"match"`` (N_bo = N_ao = N_uo + 1),
capped at ``max_n`` = 20 steps (0.5 s at 40 Hz, about half a gait cycle, so the outer
points stay within the same swing/stance episode as closely as the occlusion allows).
A fixed integer may be configured instead.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), §5.4.
Catmull, E.; Rom, R. A class of local interpolating splines. In Computer Aided Geometric
Design; Barnhill, R.E., Riesenfeld, R.F., Eds.; Academic Press: New York, 1974; 317–326.
"""
from __future__ import annotations

import numpy as np

from gaitval.errors import ConfigError
from gaitval.registry import Registry

OCCLUSION_HANDLERS = Registry("occlusion handler")

#: eq. (17) basis matrix (the ½ applied separately)
CATMULL_ROM_M = np.array([[0.0, 2.0, 0.0, 0.0],
                          [-1.0, 0.0, 1.0, 0.0],
                          [2.0, -5.0, 4.0, -1.0],
                          [-1.0, 3.0, -3.0, 1.0]])


def catmull_rom(p0, p1, p2, p3, n_uo: int) -> np.ndarray:
    """Virtual observations y'_{k+1..k+N_uo} of eq. (17), shape (n_uo, dim).

    Parameters
    ----------
    p0, p1, p2, p3 : array-like (dim,)
        y_{k−N_bo}, y_k, y_{k+N_uo+1}, y_{k+N_uo+N_ao+1}.
    n_uo : int
        Number of hidden steps.
    """
    P = np.array([p0, p1, p2, p3], dtype=float)
    return _weights(int(n_uo)) @ P                                    # eq. (17)


_WEIGHTS: dict[int, np.ndarray] = {}


def _weights(n_uo: int) -> np.ndarray:
    """½ [1 τ τ² τ³] M of eq. (17) for τ = i/(N_uo+1), i = 1..N_uo (cached per N_uo)."""
    w = _WEIGHTS.get(n_uo)
    if w is None:
        tau = np.arange(1, n_uo + 1) / (n_uo + 1.0)                  # τ = i/(N_uo+1)
        T = np.column_stack([np.ones_like(tau), tau, tau ** 2, tau ** 3])
        w = _WEIGHTS[n_uo] = 0.5 * T @ CATMULL_ROM_M                 # (½ T) M, as before
        w.flags.writeable = False
    return w


class OcclusionHandler:
    """Role base: the predict-only behaviour (never acts)."""

    def delay(self, n_uo: int) -> int | None:
        return None

    def n_before(self, n_uo: int) -> int:
        return 0

    def n_after(self, n_uo: int) -> int:
        return 0

    def virtual_observations(self, p0, p1, p2, p3, n_uo: int) -> np.ndarray:
        raise NotImplementedError


@OCCLUSION_HANDLERS.register("predict_only")
class PredictOnly(OcclusionHandler):
    """Hidden leg = Kalman prediction (seed 000 §5.3, Methods 1 and 2)."""


def _steps(v, n_uo: int, max_n: int, what: str) -> int:
    if v == "match":
        return max(1, min(n_uo + 1, max_n))
    try:
        iv = int(v)
    except (TypeError, ValueError):
        iv = -1
    if iv < 1:
        raise ConfigError(f"{what} must be 'match' or an integer ≥ 1, got {v!r}")
    return iv


@OCCLUSION_HANDLERS.register("catmull_rom")
class CatmullRomInterpolation(OcclusionHandler):
    """Catmull–Rom virtual observations and re-filtering (seed 000 §5.4, Method 3).

    Parameters
    ----------
    n_bo, n_ao : int or "match"
        N_bo, N_ao of eq. (17) (see the module notes for the default).
    max_n : int
        Cap of N_bo, N_ao under ``"match"``.
    min_n_uo : int
        Shortest occlusion (steps) that is interpolated.
    """

    def __init__(self, n_bo: int | str = "match", n_ao: int | str = "match",
                 max_n: int = 20, min_n_uo: int = 1):
        self.n_bo = n_bo
        self.n_ao = n_ao
        self.max_n = max_n
        self.min_n_uo = min_n_uo

    def n_before(self, n_uo):
        return _steps(self.n_bo, n_uo, self.max_n, "n_bo")

    def n_after(self, n_uo):
        return _steps(self.n_ao, n_uo, self.max_n, "n_ao")

    def delay(self, n_uo):
        if n_uo < self.min_n_uo:
            return None
        return self.n_after(n_uo)

    def virtual_observations(self, p0, p1, p2, p3, n_uo):
        return catmull_rom(p0, p1, p2, p3, n_uo)
