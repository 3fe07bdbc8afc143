"""Occlusion handlers: what a tracker does about a leg that was hidden (UO) for a while.

Role ``occlusion``: the tracker calls ``begin(run)`` once (per-run state, or None),
``after_scan(state, run, k)`` after every scan and ``finish(state, run)`` at the end.  A
handler acts on the run through its small interface: the legs' histories
(``run.legs[f].z``, ``.real``, ``.post``, ``.interpolated``), ``run.replay(ka, k)`` (filter
both legs again over ka+1..k with the stored observations) and ``run.resync(k)``.

Helpers the Catmull–Rom handler is built from: ``delay(n_uo)`` says how many steps after the
leg reappears the handler acts (``None``: never), ``virtual_observations(p0, p1, p2, p3,
n_uo)`` returns the observations to re-filter the hidden steps with, and ``n_before(n_uo)``
/ ``n_after(n_uo)`` give N_bo / N_ao, where the outer control points are taken.

Notes
-----
seed000 eq. (17), Catmull–Rom: with the leg observed at k and at k+N_uo+1 and hidden in
between, the virtual observations are

    y'_{k+i} = ½ [1 τ τ² τ³] M [y_{k−N_bo}; y_k; y_{k+N_uo+1}; y_{k+N_uo+N_ao+1}],
    M = [[0, 2, 0, 0], [−1, 0, 1, 0], [2, −5, 4, −1], [−1, 3, −3, 1]],
    τ = i/(N_uo + 1), i = 1..N_uo,

and the Kalman filter is run again from step k with them (§5.4).

N_bo and N_ao are not given in the paper.  seed000 eq. (17) is the *uniform* Catmull–Rom spline:
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

from dataclasses import dataclass

import numpy as np

from gaitval.errors import ConfigError
from gaitval.registry import Registry
from gaitval.track.params import NO_SOURCE, declared, param

OCCLUSION_HANDLERS = Registry("occlusion handler",
                              table="gaitval.track.roles")

#: seed000 eq. (17) basis matrix (the ½ applied separately)
CATMULL_ROM_M = np.array([[0.0, 2.0, 0.0, 0.0],
                          [-1.0, 0.0, 1.0, 0.0],
                          [2.0, -5.0, 4.0, -1.0],
                          [-1.0, 3.0, -3.0, 1.0]])


def catmull_rom(p0, p1, p2, p3, n_uo: int) -> np.ndarray:
    """Virtual observations y'_{k+1..k+N_uo} of seed000 eq. (17), shape (n_uo, dim).

    Parameters
    ----------
    p0, p1, p2, p3 : array-like (dim,)
        y_{k−N_bo}, y_k, y_{k+N_uo+1}, y_{k+N_uo+N_ao+1}.
    n_uo : int
        Number of hidden steps.
    """
    P = np.array([p0, p1, p2, p3], dtype=float)
    return _weights(int(n_uo)) @ P                                    # seed000 eq. (17)


_WEIGHTS: dict[int, np.ndarray] = {}


def _weights(n_uo: int) -> np.ndarray:
    """½ [1 τ τ² τ³] M of seed000 eq. (17) for τ = i/(N_uo+1), i = 1..N_uo (cached per
    N_uo)."""
    w = _WEIGHTS.get(n_uo)
    if w is None:
        tau = np.arange(1, n_uo + 1) / (n_uo + 1.0)                  # τ = i/(N_uo+1)
        T = np.column_stack([np.ones_like(tau), tau, tau ** 2, tau ** 3])
        w = _WEIGHTS[n_uo] = 0.5 * T @ CATMULL_ROM_M                 # (½ T) M, as before
        w.flags.writeable = False
    return w


class OcclusionHandler:
    """Role base: the predict-only behaviour (never acts)."""

    def begin(self, run):
        """Per-run state (None when the handler keeps none)."""
        return None

    def after_scan(self, state, run, k: int) -> None:
        """Called after scan k has been associated and corrected."""

    def finish(self, state, run) -> None:
        """Called after the last scan."""

    def delay(self, n_uo: int) -> int | None:
        return None

    def n_before(self, n_uo: int) -> int:
        return 0

    def n_after(self, n_uo: int) -> int:
        return 0

    def virtual_observations(self, p0, p1, p2, p3, n_uo: int) -> np.ndarray:
        raise NotImplementedError


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


@declared
@dataclass(eq=False)
class CatmullRomInterpolation(OcclusionHandler):
    """Catmull–Rom virtual observations and re-filtering (seed 000 §5.4, Method 3)."""

    n_bo: int | str = param("match", "scans", NO_SOURCE + " (not in the paper; module notes)",
                            "N_bo of seed000 eq. (17), or match: N_uo + 1")
    n_ao: int | str = param("match", "scans", NO_SOURCE + " (not in the paper; module notes)",
                            "N_ao of seed000 eq. (17), or match: N_uo + 1")
    max_n: int = param(20, "scans", NO_SOURCE + " (about half a gait cycle at 40 Hz)",
                       "cap of N_bo, N_ao under match")
    min_n_uo: int = param(1, "scans", NO_SOURCE, "shortest occlusion that is interpolated")

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

    # -- the handler's work in a run (seed 000 §5.4) --------------------------------------
    def begin(self, run):
        return _Pending(last_real=[run.k0, run.k0], due=[], next_due=run.n)

    def after_scan(self, st, run, k):
        last_real = st.last_real
        L, R = run.legs
        if L.real[k]:
            if last_real[0] < k - 1:              # leg reappears after k−1−last UO scans
                self._reappeared(st, 0, last_real[0], k)
            last_real[0] = k
        if R.real[k]:
            if last_real[1] < k - 1:
                self._reappeared(st, 1, last_real[1], k)
            last_real[1] = k
        if k >= st.next_due:                      # (next_due = n while nothing is due)
            now = [p for p in st.due if p[0] <= k]
            st.due = [p for p in st.due if p[0] > k]
            for _, f, ka, m in sorted(now, key=lambda p: (p[2], p[1])):
                self.refilter(run, f, ka, m, k)
            run.resync(k)
            st.next_due = min((p[0] for p in st.due), default=run.n)

    def _reappeared(self, st, f: int, last: int, k: int) -> None:
        d = self.delay(k - last - 1)
        if d is not None:
            st.due.append((k + d, f, last, k))
            st.next_due = min(st.next_due, k + d)

    def finish(self, st, run):
        for _, f, ka, m in sorted(st.due, key=lambda p: (p[2], p[1])):
            self.refilter(run, f, ka, m, run.n - 1)

    def refilter(self, run, f: int, ka: int, m: int, k_now: int) -> None:
        """Virtual observations for leg f over ka+1..m−1, then both legs filtered again
        from ka to k_now ("all state parameters are updated", seed 000 §5.4)."""
        run.refiltered.append((f, ka, k_now))
        leg, k0 = run.legs[f], run.k0
        n_uo = m - ka - 1
        i0 = ka - self.n_before(n_uo)
        p1, p2 = leg.z[ka], leg.z[m]
        p0 = next((leg.z[i] for i in range(max(i0, k0), k0 - 1, -1) if leg.real[i]), None)
        if p0 is None:                             # nothing observed that early: the estimate
            p0 = run.filter.pos(leg.post[max(i0, k0)])
        p3 = next((leg.z[i] for i in range(min(m + self.n_after(n_uo), k_now), m - 1, -1)
                   if leg.real[i]), p2)
        virt = self.virtual_observations(p0, p1, p2, p3, n_uo).tolist()   # seed000 eq. (17)
        for i in range(n_uo):
            leg.z[ka + 1 + i] = (virt[i][0], virt[i][1])
            leg.interpolated[ka + 1 + i] = True
        run.resync(ka)
        run.replay(ka, k_now)


@dataclass
class _Pending:
    """Catmull–Rom per-run state: the last observed scan of each leg and the re-filters
    waiting for their N_ao outer observations, as ``(due_k, leg, k_last_seen, k_back)``."""

    last_real: list
    due: list
    next_due: int
