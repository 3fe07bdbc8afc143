"""leg_tracker's rules as a baseline people tracker (Leigh et al., ICRA 2015).

The crowd benchmark's baseline row (:mod:`gaitval.crowd.bench`): gaitval's people tracker
with the parts of leg_tracker's ``joint_leg_tracker.py`` that decide who is a person —

* confirmation: :class:`LegTravel`, each leg's filtered path since the pair formed longer
  than ``dist_travelled_together_to_initiate_leg_pair`` = 0.5 m, both legs seen;
* appearance: leg_tracker's leg classifier and its confidence rule
  (``leg_forest``, :mod:`gaitval.track.appearance`);
* deletion: a person ends when its position variance passes ``max_std`` = 0.9 m, 3.0 s
  unobserved at 10 Hz (``unsupported_time``, the value of docs/people.md); no re-finding
  (leg_tracker starts a new id);
* no gait model: leg_tracker's constant-velocity person and leg filters.

The confirmer is handed to the tracker as a built part, not registered: no method of
:data:`gaitval.methods.METHODS` uses it.
"""
from __future__ import annotations

import copy
import copy
import math

from gaitval.track.lifecycle import Confirmer


class LegTravel(Confirmer):
    """leg_tracker's confirmation: each leg has travelled a stated path since the pair was
    formed, both legs are observed on the scan (module notes, ``leg_travel``).

    leg_tracker (``joint_leg_tracker.py``) keeps one constant-velocity Kalman filter per
    leg (process std ``0.5·Δt`` on position and velocity per step, observation std 0.1 m,
    P₀ = 0.5·I) and adds to the leg's ``dist_travelled`` every filter step longer than
    ``min_step_m`` = 0.01 m ("small distance changes ... likely caused by changes in
    observation angle"); a potential leg pair becomes a person when both legs are matched
    on the current scan and each has travelled more than
    ``dist_travelled_together_to_initiate_leg_pair`` = 0.5 m since the pair was formed
    (and a leg is in free space: the tracker's static-map test, :func:`gaitval.track.
    peoplepass._on_static`).  Here each tentative person carries that filter for each leg,
    fed with the leg's observation (``person.z``), and the pair is formed at the person's
    birth::

        s_f ← Σ_{k'} |p̂_f(k') − T_{k'}(p̂_f(k'−1))| · [> 0.01 m]      (f = L, R)
        confirmed  ⇔  both legs observed on k  ∧  min(s_L, s_R) > 0.5 m

    T_k carries the previous filter state into the current sensor frame with the sensor's
    own motion from the ``ego_motion`` role (:meth:`scan`; leg_tracker filters in its
    ``fixed_frame``, the odometry frame on its general benchmarks).  Where that motion is
    unknown (a new ego-motion segment) T is the identity: the step is measured in the
    sensor frame, which is leg_tracker's own setting on its following benchmarks
    (``fixed_frame`` = ``base_laser_link``, ``person_following_outdoor_1_joint_leg.launch``
    of angusleigh/leg_tracker_benchmarks), since no odometry is known there either.

    Parameters
    ----------
    min_travel_m : float
        leg_tracker's ``dist_travelled_together_to_initiate_leg_pair`` (0.5 m).
    min_step_m : float
        leg_tracker's 0.01 m below which a filter step is not counted.
    std_obs_m, p0, process_std_per_s : float
        leg_tracker's leg filter (0.1 m, 0.5, 0.5 m/s · Δt: its 0.05 at 10 Hz, 0.0667 at
        7.5 Hz, 0.0333 at 15 Hz).
    percentile, assoc_extra_m : float
        leg_tracker's leg gate: an observation at Mahalanobis distance ≥ z =
        Φ⁻¹(1 − (1 − 0.90)/2) = 1.645 with cov = P_xx + (σ_o + 0.4)² is not this leg's; it
        would start a new leg track, so both legs' paths restart from zero (a new pair).
    """

    def __init__(self, min_travel_m: float = 0.5, min_step_m: float = 0.01,
                 std_obs_m: float = 0.1, p0: float = 0.5, process_std_per_s: float = 0.5,
                 percentile: float = 0.90, assoc_extra_m: float = 0.4):
        self.percentile = percentile
        self.assoc_extra_m = assoc_extra_m
        # scipy here, not at the top: the Snakefile imports this module (the role registries)
        from scipy.stats import norm

        self.gate2 = float(norm.ppf(1.0 - (1.0 - percentile) / 2.0)) ** 2     # 1.645²
        self.var_assoc = (std_obs_m + assoc_extra_m) ** 2
        self.min_travel_m = min_travel_m
        self.min_step_m = min_step_m
        self.std_obs_m = std_obs_m
        self.p0 = p0
        self.process_std_per_s = process_std_per_s
        self.dt = 0.1
        self._motion = None

    def bind(self, dt, leg_width_m: float = 0.10):
        out = copy.copy(self)          # the declared values; dt for this run
        out.dt = float(dt)
        return out

    def scan(self, k: int, motion) -> None:
        """The sensor's motion from scan k−1 to k: (dx, dy, dθ) of its pose at k in its
        frame at k−1, or None when unknown (module notes)."""
        self._motion = motion

    def new_memory(self):
        # per leg: leg_tracker's filter state [x, y, vx, vy], its per-axis 2×2 covariance
        # (the same for x and y: isotropic P₀, Q and R), and the path travelled
        return {"kf": [None, None], "path": [0.0, 0.0]}

    def _carry(self, st):
        """A filter state of the previous scan in the current sensor frame."""
        m = self._motion
        if m is None:
            return st
        dx, dy, dth = m
        c, s = math.cos(dth), math.sin(dth)
        x, y, vx, vy = st
        x, y = x - dx, y - dy
        return [c * x + s * y, -s * x + c * y, c * vx + s * vy, -s * vx + c * vy]

    def step(self, person, k):
        mem = person.confirm_memory
        dt = self.dt
        q = (self.process_std_per_s * dt) ** 2
        r = self.std_obs_m ** 2
        for f in (0, 1):
            z = person.z[f]
            kf = mem["kf"][f]
            if kf is None:
                if z is not None:
                    mem["kf"][f] = ([z[0], z[1], 0.0, 0.0], (self.p0, 0.0, self.p0))
                continue
            st, (pxx, pxv, pvv) = kf
            old = self._carry(st)
            # predict (constant velocity, F = [[1, Δt], [0, 1]] per axis, Q = q·I)
            x, y, vx, vy = old[0] + dt * old[2], old[1] + dt * old[3], old[2], old[3]
            pxx, pxv, pvv = (pxx + 2 * dt * pxv + dt * dt * pvv + q, pxv + dt * pvv,
                             pvv + q)
            if z is not None and ((z[0] - x) ** 2 + (z[1] - y) ** 2
                                  >= self.gate2 * (pxx + self.var_assoc)):
                # outside leg_tracker's leg gate: leg_tracker would start a new leg track
                # here, and a new potential pair whose path starts at zero
                mem["kf"][f] = ([z[0], z[1], 0.0, 0.0], (self.p0, 0.0, self.p0))
                mem["path"] = [0.0, 0.0]
                continue
            if z is not None:                                   # correct, per axis
                s_ = pxx + r
                kx, kv = pxx / s_, pxv / s_
                ex, ey = z[0] - x, z[1] - y
                x, y, vx, vy = x + kx * ex, y + kx * ey, vx + kv * ex, vy + kv * ey
                pxx, pxv, pvv = (1 - kx) * pxx, (1 - kx) * pxv, pvv - kv * pxv
            d = math.hypot(x - old[0], y - old[1])
            if d > self.min_step_m:
                mem["path"][f] += d
            mem["kf"][f] = ([x, y, vx, vy], (pxx, pxv, pvv))
        if not (person.seen[0] and person.seen[1]):
            return False
        return min(mem["path"]) > self.min_travel_m


def baseline_kind() -> dict:
    """The baseline's ``kind`` spec: the ``people`` method's sensing (detector, leg
    filter, ego-motion, static map) with leg_tracker's rules (module notes)."""
    from gaitval.methods import METHODS
    kind = copy.deepcopy(METHODS["people"]["kind"])
    # legs associated one by one, as leg_tracker's GNN does (not gaitval's pair rule)
    kind.update({"confirmer": LegTravel(), "refind": "none", "pair_swing_mps": None,
                 "motion": {"name": "constant_velocity"},
                 "appearance": {"name": "leg_forest"},
                 "deleter": {"name": "unsupported_time", "max_unsupported_s": 3.0,
                             "tentative_unsupported_s": 0.2}})
    kind.pop("passes", None)
    return kind
