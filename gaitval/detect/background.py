"""Static background removal for a fixed laser range sensor.

Walls, the chair, the calibration poles and the TUG turn marker do not move during a
trial; the legs cross any one beam only for part of it.  gaitval therefore models the
background per beam as a high percentile of that beam's ranges over the whole trial
(offline, as the paper's gait analysis runs after the test) and keeps a return as
*foreground* only if it is clearly in front of it::

    b_i = percentile_q({l_i(k)}_k)          (no return counts as +∞)
    foreground_i(k)  ⇔  l_i(k) < b_i − margin

With ``q = 95`` a beam may be covered by a leg for up to 95 % of the scans (the seated
start and end of a TUG cover a few beams for a second or two) and still get its true
background; ``margin_m = 0.10`` is > 3× the UTM-30LX ranging accuracy (±0.03 m, seed 000
Table 1), so range noise on a wall never becomes a leg.  Background returns are replaced by
+∞ (like "no return"), so a leg in front of a wall keeps both of its edges.

What it cannot do: a leg within ``margin_m`` of a wall or object behind it is removed
with the background; a person standing still for more than (100 − q) % of a trial would
become background.
"""
from __future__ import annotations

import numpy as np

from gaitval.registry import Registry

BACKGROUNDS = Registry("background")

#: stand-in for "no return" while computing percentiles (inf breaks interpolation)
_FAR = 1.0e9


class Background:
    """Role base: returns a masked copy of the ranges with background set to +inf."""

    def mask(self, ranges: np.ndarray) -> np.ndarray:
        raise NotImplementedError


@BACKGROUNDS.register("percentile")
class PercentileBackground(Background):
    """Per-beam high-percentile background (see the module docstring).

    Parameters
    ----------
    q : float
        Percentile (0–100) of each beam's ranges taken as its background.
    margin_m : float
        A return must be this much closer than the background to be foreground.
    """

    def __init__(self, q: float = 95.0, margin_m: float = 0.10):
        self.q = q
        self.margin_m = margin_m

    def model(self, ranges: np.ndarray) -> np.ndarray:
        """Background range per beam, shape (n_beams,); ``inf`` where mostly no return."""
        r = np.where(np.isfinite(ranges), ranges, _FAR)
        b = np.percentile(r, self.q, axis=0, method="higher")
        return np.where(b >= _FAR, np.inf, b)

    def mask(self, ranges: np.ndarray) -> np.ndarray:
        b = self.model(ranges)
        with np.errstate(invalid="ignore"):
            fg = np.isfinite(ranges) & (ranges < b - self.margin_m)
        return np.where(fg, ranges, np.inf)


@BACKGROUNDS.register("none")
class NoBackground(Background):
    """Keep every return (for scans already free of background, e.g. in tests)."""

    def mask(self, ranges: np.ndarray) -> np.ndarray:
        return np.where(np.isfinite(ranges), ranges, np.inf)
