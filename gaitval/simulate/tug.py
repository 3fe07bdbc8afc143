"""The Timed Up and Go scene (seed 000): chair, 3 m walk, turn marker, poles, fixed LRS.

Every number here is a physical or anthropometric assumption documented in
``docs/simulator.md``; none is tuned towards a tracker's outcome.

References
----------
Yorozu A, Moriguchi T, Takahashi M. Improved leg tracking considering gait phase and
spline-based interpolation during turning motion in walk tests. Sensors 2015;15:22451–22472
(TUG: chair, 3 m, marker, two calibration poles, LRS at 0.27 m, 7 young adults × 4 trials).
"""
from __future__ import annotations

import numpy as np

from gaitval.simulate.kinematics import make_path, plan_steps
from gaitval.simulate.scene import ID_CHAIR, ID_MARKER, ID_POLE, Walker
from gaitval.simulate.trialsim import POLE_RADIUS_M, TrialSim, _walls

#: The turn marker (a cone, 0.06 m radius at shin height) 3 m from the chair's front edge on
#: the course axis: "walks three meters, turns around a marker, walks back to the chair and
#: sits down" (seed 000 §1; Podsiadlo & Richardson 1991: a line 3 m away).
TUG_MARKER_XY = (3.0, 0.0)
#: The marker cone's radius at shin height (m) and the clearance (m) its surface keeps from
#: a shank's surface when the inner foot swings past it.
MARKER_RADIUS_M = 0.06
MARKER_CLEARANCE_M = 0.05
#: Where the turn to sit begins: the body is this far in front of its seated place.
TURN_TO_SIT_FROM_M = 0.45
#: Feet under the chair's front edge when seated (x), on the course axis (y = 0).
SEAT_X_M = 0.12
#: Half the distance between the feet when seated, at the start and again at the end (m):
#: seated people keep the feet about hip width apart.
SEATED_HALF_WIDTH_M = 0.10
#: Pivot steps of the turn to sit (180° in equal parts), the closing step not counted:
#: 60° per step, a turn without crossing the legs (docs/simulator.md, issue 34).
TURN_TO_SIT_STEPS = 3
#: The capture ends this long after the participant is seated (s, uniform): the timed
#: span of the TUG ends when the participant sits (Podsiadlo & Richardson 1991).
END_AFTER_SEATED_S = (0.1, 0.3)


def turn_radius(gp, leg_width_m: float) -> float:
    """Radius of the body path around the marker: the tightest the participant's turning
    steps allow.

    No TUG paper gives the radius, so it follows from the geometry of the steps: in the turn
    the steps shorten to ``L_t = turn_step_factor · L`` (+ 2 SD of step variability), a
    step on the path of radius ``r`` turns the body by ``L_t / r``, and the inner foot
    (at ``r − W/2``) swings straight from one foothold to the next, a chord that passes
    ``(r − W/2) cos(L_t / r)`` from the marker's axis.  The radius is the smallest ``r`` at
    which that chord keeps the shank (half leg width) :data:`MARKER_CLEARANCE_M` clear of
    the cone (:data:`MARKER_RADIUS_M`), solved by bisection.
    """
    lt = gp.turn_step_factor * gp.step_length_m * (1 + 2 * gp.step_cv)
    need = MARKER_RADIUS_M + leg_width_m / 2 + MARKER_CLEARANCE_M + 2 * gp.place_sd_m
    lo, hi = max(gp.step_width_m / 2 + need, lt / np.pi) + 1e-6, 2.0
    for _ in range(60):
        r = 0.5 * (lo + hi)
        if (r - gp.step_width_m / 2) * np.cos(min(lt / r, np.pi)) >= need:
            hi = r
        else:
            lo = r
    return float(hi)


def tug_path(r: float):
    """Out and back around the marker: the TUG course as a walking path.

    From the seat (``SEAT_X_M``, 0) straight to the tangent of the circle of radius ``r``
    (:func:`turn_radius`) around the marker (passing it on its right), a left turn around
    it by ``π + 2α`` (``α = asin(r / d)``, ``d`` the seat-to-marker distance), and the
    mirrored tangent back towards the chair, ending :data:`TURN_TO_SIT_FROM_M` before the
    seat where the turn to sit begins (``plan_steps(end_pose=...)``).
    """
    mx, my = TUG_MARKER_XY
    d = float(np.hypot(mx - SEAT_X_M, my))
    alpha = float(np.arcsin(r / d))
    leg = float(np.sqrt(d * d - r * r))                # tangent from the seat to the circle
    return make_path((SEAT_X_M, 0.0), -alpha, [("line", leg, "forward"),
                                                ("arc", r, np.pi + 2 * alpha, "turning"),
                                                ("line", leg - TURN_TO_SIT_FROM_M, "return")])


def build_tug(rng, study, subj, gp, trial, rep, sensor_pose, cfg) -> TrialSim:
    """Timed Up and Go: rise, walk 3 m, turn around a marker, walk back, turn, sit.

    Field frame: the chair's front edge at x = 0, facing +x; feet start at
    x = :data:`SEAT_X_M`.  The path (:func:`tug_path`) is out and back around the marker
    at (3, 0): out on the marker's right, a left turn of radius :func:`turn_radius`
    around it, back on the tangent towards the chair.  Where the return line ends
    (:data:`TURN_TO_SIT_FROM_M` before the seat) the participant turns to sit in
    :data:`TURN_TO_SIT_STEPS` pivot steps without crossover that end at the seat facing
    +x, the other foot joins at hip width (:data:`SEATED_HALF_WIDTH_M`, as at the start),
    and they sit down: the descent starts as the last pivot step lands (the closing step
    is taken while lowering).
    """
    t_rise = float(rng.uniform(0.5, 0.9))
    rise_dur = float(rng.normal(0.9, 0.08))
    t0 = t_rise + 0.6 * rise_dur                       # gait initiation during the rise
    path = tug_path(turn_radius(gp, subj["leg_width_m"]))
    plan = plan_steps(path, gp, rng, t0=t0, first_side=int(rng.integers(0, 2)),
                      end_pose=(SEAT_X_M, 0.0, 2 * np.pi, TURN_TO_SIT_STEPS),
                      start_half_width=SEATED_HALF_WIDTH_M, end_label="turn_to_sit",
                      end_half_width=SEATED_HALF_WIDTH_M)
    # the descent begins as the last pivot step lands: the trailing foot joins while the
    # body lowers (before issue 34 it began 0.15 s after the closing step; the change
    # brings the return phase from 4.5 s towards seed 000 Table 4's 3.34 s)
    t_sit = float(plan.t_contact[-2])
    sit_dur = float(rng.normal(1.0, 0.08))
    t_end = t_sit + sit_dur + float(rng.uniform(*END_AFTER_SEATED_S))

    def sit(t):
        up = np.clip((t - t_rise) / rise_dur, 0, 1)
        down = np.clip((t - t_sit) / sit_dur, 0, 1)
        ss = lambda x: x * x * (3 - 2 * x)
        return 1 - ss(up) + ss(down)

    def ptilt(t):
        u = np.clip((t - t_rise) / rise_dur, 0, 1)
        d = np.clip((t - t_sit) / sit_dur, 0, 1)
        return np.deg2rad(15.0) * (np.sin(np.pi * u) ** 2 + np.sin(np.pi * d) ** 2)

    walker = Walker(plan=plan, gp=gp, leg_width_m=subj["leg_width_m"], sit=sit,
                    sensor_height_m=cfg["sensor_height_m"],
                    posture_tilt=ptilt)
    chair = [(-0.02, 0.22), (-0.02, -0.22), (-0.42, 0.22), (-0.42, -0.22)]
    circles = [(x, y, 0.015, ID_CHAIR) for x, y in chair]
    circles.append((*TUG_MARKER_XY, MARKER_RADIUS_M, ID_MARKER))
    poles = np.array([[1.4, -1.0], [3.9, 1.3]])
    circles += [(x, y, POLE_RADIUS_M, ID_POLE) for x, y in poles]
    # phase: forward until the first turning step, turning until the first return step
    labs = plan.label.copy()
    first_turn = int(np.argmax(labs == "turning"))
    first_ret = int(np.argmax(labs == "return"))
    t_turn0 = plan.t_off[first_turn]                  # lift-off of the first turning step
    t_turn1 = plan.t_contact[first_ret]                # first contact on the return line

    def phase(t):
        return np.where(t < t_turn0, "forward", np.where(t < t_turn1, "turning", "return"))

    return TrialSim(study=study, protocol="tug", subject=subj["subject"], trial=trial,
                    walker=walker, sensor="utm30lx", sensor_height_m=cfg["sensor_height_m"],
                    mocap_rate_hz=cfg["mocap_rate_hz"], t_end_s=t_end,
                    circles=np.array(circles, dtype=float), walls=_walls(-2.0, 5.5, -2.5, 2.5),
                    poles=poles, fixed_pose=sensor_pose, phase_fn=phase, repetition=rep,
                    speed="fast", variant={"t_phase": (t_turn0, t_turn1)})
