"""Observation sources: where the tracker takes each scan's leg observations from.

A source has ``len(source)`` scans, ``array(k)`` (the ``(J, 2)`` observations of scan k
without any prediction, for the initialiser) and ``at(k, prior) -> (obs, patterns)`` (the
observations the tracker gates at scan k, as a list of ``(x, y)`` floats, and their
patterns; ``prior`` is the pair of predicted leg states, None at initialisation).

* :class:`DetectionSeries`: detections computed beforehand for the whole trial (the
  five-pattern detector of seeds 000 and 001 ignores the prediction).
* :class:`WindowedDetections`: a detector that looks only inside a window placed from the
  prediction (seed 002 §II); it implements
  ``observe(scans, k, predicted, leg_width_m) -> ((J, 2) array, patterns)`` where
  ``predicted`` is None or, per leg, ``((x, y), S)`` with S the 2×2 innovation covariance
  of seed000 eq. (12).
"""
from __future__ import annotations

import numpy as np


class DetectionSeries:
    """Precomputed per-scan detections (the tracker's plain input)."""

    def __init__(self, xy: list[np.ndarray], patterns: list[list[str]]):
        self._patterns = patterns
        arrs = [np.asarray(o, dtype=float) for o in xy]
        self._arrays = [o if o.ndim == 2 and o.shape[1:] == (2,) else o.reshape(-1, 2)
                        for o in arrs]
        # and plain Python floats for the loop (numpy scalars are several times slower)
        self._lists = [o.tolist() for o in self._arrays]

    def __len__(self) -> int:
        return len(self._arrays)

    def array(self, k: int) -> np.ndarray:
        return self._arrays[k]

    def arrays(self) -> list[np.ndarray]:
        """Every scan's :meth:`array`."""
        return self._arrays

    def at(self, k: int, prior):
        return self._lists[k], self._patterns[k]

    def precomputed(self) -> tuple[list, list]:
        """``(lists(), patterns)``: what :meth:`at` returns for every scan, for a loop that
        reads them directly."""
        return self._lists, self._patterns

    def lists(self) -> list[list[list[float]]]:
        """Every scan's observations as lists of ``[x, y]`` floats (``array(k).tolist()``)."""
        return self._lists


class WindowedDetections:
    """Detections made scan by scan from the prediction (see module notes)."""

    def __init__(self, detector, scans, leg_width_m: float, filter=None):
        self.detector, self.scans, self.leg_width_m = detector, scans, leg_width_m
        self.filter = filter

    def __len__(self) -> int:
        return self.scans.n_scans

    def array(self, k: int) -> np.ndarray:
        return np.asarray(self.detector.observe(self.scans, k, None, self.leg_width_m)[0],
                          dtype=float).reshape(-1, 2)

    def at(self, k: int, prior):
        predicted = None
        if prior is not None and self.filter is not None:
            F = self.filter
            predicted = tuple((F.pos(s), F.innovation_cov(s)) for s in prior)
        xy, pats = self.detector.observe(self.scans, k, predicted, self.leg_width_m)
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        return xy.tolist(), list(pats)
