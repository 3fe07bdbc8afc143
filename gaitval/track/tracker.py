"""The leg tracker: one part per role, wired in seed 000's per-scan order.

Per scan k (seed 000 §5): **predict** both legs (seed000 eq. (7)–(8), input u from the
gait phase at k−1, eq. (18)–(20)); take the scan's **observations** (precomputed
detections, or a detector that places its window from the prediction); **gate** them per
leg (seed000 eq. (11)–(13) or seed001 Table 1); **associate** (seed000 eq. (9)–(10), GNN or
the gait-phase rule of §5.2); **correct** (seed000 eq. (14)–(16); a leg without an
observation keeps its prediction and gets the UO pattern) and identify the **gait phase**
(seed000 eq. (3)–(5)); **handle occlusion** (nothing, or Catmull–Rom virtual observations
and re-filtering, seed000 eq. (17)).  :meth:`Tracker.track` is that order written as one
call per role and holds no role's arithmetic; the speed is in the calls: each role builds
a *kernel* for the run (a closure with its parameters and the run's histories bound, e.g.
the χ² gate of both legs in one pass over the scan's observations), and
:class:`~gaitval.track.trackingrun.TrackingRun` keeps the per-leg histories
(:class:`~gaitval.track.leg.LegTrack`) the roles read and write.

Initialisation is a role too (``init``; TUG: the closest plausible pair of observations,
both legs at rest, :mod:`gaitval.track.init`).  Which of the two tracks is the *left* leg
is decided after the run from the walking direction (``sides="walking_direction"``,
:func:`gaitval.track.leg.handedness`), or kept as initialised (``"as_initialised"``).

Time step.  Δt is the sensor's scan period: ``dt_s`` if configured, else the median
timestamp difference; a gap of n periods in the timestamps (dropped scans) is predicted
as one step of n·Δt, so timestamp jitter does not enter the model.

References
----------
Yorozu, A.; Moriguchi, T.; Takahashi, M. Improved Leg Tracking Considering Gait Phase and
Spline-Based Interpolation during Turning Motion in Walk Tests. Sensors 2015, 15,
22451–22472. doi:10.3390/s150922451
"""
from __future__ import annotations

import numpy as np

from gaitval.track.associate import ASSOCIATORS
from gaitval.track.gate import GATES
from gaitval.track.init import INITIALISERS
from gaitval.track.kalman import FILTERS
from gaitval.track.leg import (TRACK_COLUMNS, TrackResult, empty_result,  # noqa: F401
                               handedness, swap_sides)
from gaitval.track.motion import MOTION_MODELS
from gaitval.track.observations import DetectionSeries, WindowedDetections
from gaitval.track.occlusion import OCCLUSION_HANDLERS
from gaitval.track.phase import PHASE_MODELS
from gaitval.track.trackingrun import SWING as _SWING  # noqa: F401  (the people tracker's)
from gaitval.track.trackingrun import TrackingRun, step_durations  # noqa: F401


class Tracker:
    """Two-leg tracker composed of one part per role.

    Parameters
    ----------
    filter, motion, phase, gate, associator, occlusion, init : str, dict or part
        Registry specs (see :mod:`gaitval.methods`) or ready objects.
    dt_s : float or None
        Scan period; None infers it from the timestamps.
    sides : {"walking_direction", "as_initialised"}
        How the left/right labels are decided (module notes).
    """

    def __init__(self, filter="kf", motion="gait_phase_accel", phase="speed_thresholds",
                 gate="chi2", associator="gnn", occlusion="predict_only",
                 init="closest_pair", dt_s: float | None = None,
                 sides: str = "walking_direction"):
        self.filter = FILTERS.build(filter)
        self.motion = MOTION_MODELS.build(motion)
        self.phase = PHASE_MODELS.build(phase)
        self.gate = GATES.build(gate)
        self.associator = ASSOCIATORS.build(associator)
        self.occlusion = OCCLUSION_HANDLERS.build(occlusion)
        self.init = INITIALISERS.build(init)
        self.dt_s = dt_s
        self.sides = sides

    def run(self, t, xy, patterns, leg_width_m: float) -> TrackResult:
        """Track both legs through precomputed per-scan observations.

        Parameters
        ----------
        t : ndarray (n_scans,)
            Scan times (sensor clock, s).
        xy : list of ndarray (J_k, 2)
            Observed leg positions per scan (sensor frame, m).
        patterns : list of list of str
            Their patterns (SL, LT, FS_O, FS_U).
        leg_width_m : float
            w_l, for the initialiser and context-dependent gates.
        """
        return self.track(t, DetectionSeries(xy, patterns), leg_width_m)

    def run_windowed(self, scans, detector, leg_width_m: float) -> TrackResult:
        """Track with a detector that places its observation window from the prediction
        (``detector.observe(scans, k, predicted)``, seed 002 §II)."""
        return self.track(scans.t, WindowedDetections(detector, scans, leg_width_m,
                                                      self.filter), leg_width_m)

    def track(self, t, source, leg_width_m: float) -> TrackResult:
        """The per-scan loop over an observation source (module notes): one call per role."""
        t = np.asarray(t, dtype=float)
        start = self.init.find(source, leg_width_m)
        if start is None:                                       # no subject found
            return empty_result(t)
        run = TrackingRun(self, t, source, leg_width_m, start)
        gate = self.gate.for_leg_width(leg_width_m).kernel(run)
        associate, update = self.associator.kernel(run)
        occlusion = self.occlusion
        state = occlusion.begin(run)
        for k in range(run.k0 + 1, run.n):
            prior = run.predict(k)                      # seed000 eq. (7)–(8), (18)–(20)
            obs, pats = source.at(k, prior)             # detections (or a windowed detector)
            cand_l, cand_r = gate(k, prior, obs)        # seed000 eq. (11)–(13)
            a, b = associate(k, prior, obs, cand_l, cand_r)     # seed000 eq. (9)–(10)
            post_l, post_r, phase = update(prior, obs, a, b)    # eq. (14)–(16), (3)–(5)
            run.commit(k, a, b, post_l, post_r, phase, obs, pats)
            occlusion.after_scan(state, run, k)         # seed000 eq. (17)
        occlusion.finish(state, run)
        res = run.result()
        if self.sides == "walking_direction" and handedness(res) < 0:
            swap_sides(res)
        return res
