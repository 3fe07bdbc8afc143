"""Observers of a people-tracker pass: told before and after each scan
(:meth:`gaitval.track.peoplepass.PeoplePass.scan`), so that profiling stays out of the loop."""
from __future__ import annotations

from time import perf_counter

import numpy as np


class ScanProfile:
    """An observer of a pass: per scan, the seconds spent, the hypotheses alive and each
    observation's static flag (benchmarks/people_tracker.py, experiments/)."""

    def __init__(self):
        self.seconds, self.alive, self.static = [], [], []
        self._t0 = 0.0

    def before(self, k: int) -> None:
        self._t0 = perf_counter()

    def after(self, k: int, run) -> None:
        self.seconds.append(perf_counter() - self._t0)
        self.alive.append(len(run.persons))
        self.static.append(run.static)

    def arrays(self):
        return (np.asarray(self.seconds), np.asarray(self.alive, dtype=np.int64), self.static)
