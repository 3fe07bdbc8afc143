"""Seed 001's treatment of an unobserved leg: the prediction is used as the observation.

Role ``occlusion`` (:mod:`gaitval.track.occlusion`).  Seed 001 §2.4.3: "If there are no
corresponding observed positions in the validation region, the predicted position
ŷ_{k/k−1} is used as an observed position and the observed leg pattern is assumed to be
UO."  Read literally, the Kalman correction is run with y_k = ŷ_{k/k−1}: the innovation is
zero, so position and velocity stay the prediction, but the covariance shrinks as after a
real observation, P = (I − K C) P.  :class:`PseudoObservation` does exactly that after the
tracker's loop committed the scan (the loop itself keeps the prediction, i.e. predict
only).  The alternative reading — predict only, P growing while the leg is hidden — is
the ``predict_only`` handler; the choice is a method parameter.

What it changes: the innovation covariance S = C P Cᵀ + R of the next scans, hence the
squared Mahalanobis costs the GNN compares (seed001 eq. (8)) and the gain with which a
reappearing leg is corrected.  It does not change the Table 1 radii (they use the speed
‖v_{k−1}‖, which a zero innovation leaves as it was) or the gait phase.

References
----------
Yorozu, A.; Nishiguchi, S.; Yamada, M.; Aoyama, T.; Moriguchi, T.; Takahashi, M. Gait
Measurement System for the Multi-Target Stepping Task Using a Laser Range Sensor. Sensors
2015, 15, 11151–11168 (seed 001), §2.4.3.
"""
from __future__ import annotations

from gaitval.track.occlusion import OcclusionHandler


class PseudoObservation(OcclusionHandler):
    """Correct an unobserved (UO) leg with its own prediction (seed 001 §2.4.3)."""

    def after_scan(self, state, run, k: int) -> None:
        L, R = run.legs                                   # (written out: once per scan)
        if L.z[k] is None:                                # UO: no real or virtual observation
            s = L.post[k]
            L.post[k] = run.filter.correct(s, s[0], s[1])         # seed001 §2.4.3: y = ŷ
        if R.z[k] is None:
            s = R.post[k]
            R.post[k] = run.filter.correct(s, s[0], s[1])         # seed001 §2.4.3: y = ŷ
