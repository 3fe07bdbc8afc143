"""Gates (validation regions): which observations may be associated with a leg.

Role ``gate``: ``admits(lam2, dist, ctx) -> bool`` for one observation and one leg, where
``lam2`` is the squared Mahalanobis distance λ² of seed 000 eq. (11), ``dist`` the Euclidean
distance to the predicted position, and ``ctx`` a dict with at least ``leg_width_m`` and
``dt`` (and, for richer gates, ``speed``, ``swing``, ``n_unobserved``).

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Sensors 2015, 15, 22451–22472 (seed 000), eq. (13).
Yorozu, A. et al. Sensors 2015, 15, 11151–11168 (seed 001), eq. (5) and §3 (fixed radii).
"""
from __future__ import annotations

from gaitval.registry import Registry

GATES = Registry("gate")


class Gate:
    """Role base.  ``needs_context = False`` lets the tracker pass ``ctx=None`` (faster)."""

    needs_context = True

    def admits(self, lam2: float, dist: float, ctx: dict) -> bool:
        raise NotImplementedError


@GATES.register("chi2")
class ChiSquareGate(Gate):
    """Mahalanobis gate λ² < G, eq. (13).

    Parameters
    ----------
    g : float
        G; seed 000 Table 2: 13.82 (χ² with 2 degrees of freedom, P_G = 0.999).
    """

    needs_context = False

    def __init__(self, g: float = 13.82):
        self.g = g

    def admits(self, lam2, dist, ctx):
        return lam2 < self.g                        # eq. (13)


@GATES.register("fixed_radius")
class FixedRadiusGate(Gate):
    """Circular gate ‖y − ŷ‖ < r_val with r_val = ``radius_leg_widths`` · w_l (seed 001 eq. 5).

    Seed 001 uses 1.5 w_l (large) and 1.0 w_l (small) for its comparison methods.
    """

    def __init__(self, radius_leg_widths: float = 1.5):
        self.radius_leg_widths = radius_leg_widths

    def admits(self, lam2, dist, ctx):
        return dist < self.radius_leg_widths * ctx["leg_width_m"]
