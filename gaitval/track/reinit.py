"""Re-initialisation after lost legs (seed 002 §II), and a pair initialiser for a laser
that faces the user.

Seed 002 §II: "To address such cases of detection loss while continuing the leg tracking,
an only-prediction KF is applied ... If detection loss occurs for a pre-specified number
of consecutive frames, we re-initialize the algorithm."

:class:`ReinitialiseAfterLost` (occlusion role ``reinit_after_lost``)
    A leg without an associated observation keeps its prediction (the loop's predict-only
    behaviour).  Once either leg has gone ``n_lost`` consecutive scans without one, the
    algorithm is due for re-initialisation: from that scan on, the handler looks at each
    scan again with the detector's predefined window (no prediction, as at the first scan)
    and, at the first one with a pair of legs, restarts both legs on it at rest
    (:meth:`~gaitval.track.trackingrun.TrackingRun.restart`; every restart is counted in
    ``TrackResult.restarts``), even if the loop has meanwhile gated an observation to the
    lost leg again.
    ``n_lost`` is not given in the paper; gaitval's default is 15 scans (0.4 s at the
    UBG-04LX-F01's 37 scans/s), about one swing of an older adult's stride (≈ 1.1 s, swing
    ≈ 36 %): a leg hidden for longer than a swing has landed where a constant-velocity
    prediction cannot know.  The new pair is labelled left/right by the same rule as the
    first scan (:class:`FacingPair`), so a re-initialisation can also undo a swap.
:class:`FacingPair` (init role ``facing_pair``)
    The closest plausible pair (:class:`~gaitval.track.init.ClosestPair`), labelled for a
    laser that faces the user (the rollator's, mounted backwards): the user's left leg is
    on the laser's right, at the smaller bearing.  ``sensor_faces_user=False`` gives the
    usual labelling (left = larger bearing) of a laser behind or beside the walker.

    **No phantom user** (issue 36): seed 002 §III.A initialises at k = 1 on the legs the
    §II detector finds in the predefined window, "both legs still in front of the
    rollator"; the paper's subjects are always there.  A robot driving through an empty
    room (leg_tracker's ``negative_2.bag``) puts chair legs, walls and door frames into
    the window on 71–94 % of its scans, and the KF and PF then tracked them to the end.
    The start is kept exactly as before (the first pair, at rest), but only when some
    pair of the trial, from that scan on, *walks with the sensor*
    (:class:`~gaitval.track.init_walking.WalkingPairCheck`: within 1.4 s the legs pass each other
    while the body stays in place w.r.t. the rollator); otherwise the run reports no
    track, as the TUG and MTST initialisers do (``keep_if_moving``).  Re-initialisation
    looks at one scan (:meth:`FacingPair.pair`) and keeps its pair.

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental validation
of human gait tracking algorithms for an intelligent robotic rollator. IEEE ICRA 2017, §II.
"""
from __future__ import annotations

from dataclasses import dataclass

from gaitval.errors import ConfigError
from gaitval.track.init import INITIALISERS, ClosestPair, keep_if_moving
from gaitval.track.init_walking import WalkingPairCheck
from gaitval.track.occlusion import OcclusionHandler
from gaitval.track.params import NO_SOURCE, declared, param


class FacingPair(ClosestPair):
    """The closest plausible pair, left = smaller bearing when the laser faces the user;
    None when no pair of the trial walks with the sensor (module notes).

    Parameters
    ----------
    max_pair_m, min_leg_widths : float
        As :class:`~gaitval.track.init.ClosestPair`.
    sensor_faces_user : bool
        True: left leg at the smaller bearing (module notes).
    require_motion : bool
        False: the first pair is kept whether or not anything walks (the rule before
        issue 36).
    min_scans : int
        A source with fewer scans (one scan: :meth:`pair`) keeps its pair; so does one
        with less than one walking window (1.4 s) from the pair's scan on, which cannot
        show a stride.
    window_s, pass_leg_widths, stay_leg_widths, max_speed_mps : float
        :class:`~gaitval.track.init_walking.WalkingPairCheck`.
    """

    def __init__(self, max_pair_m: float = 0.8, min_leg_widths: float = 0.7,
                 sensor_faces_user: bool = True, require_motion: bool = True,
                 min_scans: int = 10, window_s: float = 1.4, pass_leg_widths: float = 1.0,
                 stay_leg_widths: float = 1.0, max_speed_mps: float = 5.0):
        super().__init__(max_pair_m=max_pair_m, min_leg_widths=min_leg_widths)
        self.sensor_faces_user = bool(sensor_faces_user)
        self.require_motion = bool(require_motion)
        self.min_scans = int(min_scans)
        self.check = WalkingPairCheck(window_s=window_s, pass_leg_widths=pass_leg_widths,
                                      stay_leg_widths=stay_leg_widths,
                                      max_speed_mps=max_speed_mps)

    def find(self, source, leg_width_m):
        found = super().find(source, leg_width_m)
        if found is not None and len(source) - found[0] >= self.check.window_scans(source):
            found = keep_if_moving(self, source, found, leg_width_m)
        # else: less than one window from the pair on cannot show a stride; kept
        if found is None or not self.sensor_faces_user:
            return found
        k, il, ir = found
        return k, ir, il

    def pair(self, obs, leg_width_m: float) -> tuple[int, int] | None:
        """(i_left, i_right) of the pair in one scan's observations ``obs`` (J, 2), or None."""
        found = self.find(_OneScan(obs), leg_width_m)
        return None if found is None else (found[1], found[2])


class _OneScan:
    """An observation source of a single scan (for :meth:`FacingPair.pair`)."""

    def __init__(self, obs):
        import numpy as np
        self._obs = np.asarray(obs, dtype=float).reshape(-1, 2)

    def __len__(self) -> int:
        return 1

    def array(self, k: int):
        return self._obs


@declared
@dataclass(eq=False)
class ReinitialiseAfterLost(OcclusionHandler):
    """Predict only, then restart both legs after ``n_lost`` lost scans (module notes)."""

    n_lost: int = param(15, "scans", NO_SOURCE + " (seed002 §II gives no number; about "
                        "one swing, module notes)",
                        "consecutive scans without an observation (either leg) that "
                        "trigger the re-initialisation")
    init: dict | str | None = param(None, "-", NO_SOURCE, "the initialiser whose pair rule "
                                    "labels the new legs (registry spec; None: facing_pair)")

    def __post_init__(self):
        n_lost = self.n_lost
        if int(n_lost) < 1:
            raise ConfigError(f"reinit_after_lost: n_lost must be ≥ 1, got {n_lost!r}")
        self.n_lost = int(n_lost)
        self.init = INITIALISERS.build(self.init if self.init is not None else "facing_pair")
        if not hasattr(self.init, "pair"):
            raise ConfigError(f"reinit_after_lost: initialiser {self.init!r} cannot label "
                              "the legs of one scan", hint="use init: facing_pair")

    def begin(self, run):
        return {"pending": False}

    def after_scan(self, state, run, k):
        L, R = run.legs
        if max(L.n_unobserved, R.n_unobserved) >= self.n_lost:
            state["pending"] = True                 # detection lost for n_lost scans
        if not state["pending"]:
            return
        obs = run.source.array(k)                   # the predefined window, as at k = 1
        found = self.init.pair(obs, run.leg_width_m)
        if found is None:
            return                                  # keep predicting; try the next scan
        il, ir = found
        pats = ["SL"] * len(obs)
        run.restart(k, obs.tolist(), pats, il, ir)  # counted in TrackResult.restarts
        state["pending"] = False
