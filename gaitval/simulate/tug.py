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

from dataclasses import replace

import numpy as np
import pandas as pd

from gaitval.evaluate.tug_truth import tug_phase_bounds
from gaitval.simulate.kinematics import make_path, plan_steps
from gaitval.simulate.scene import ID_CHAIR, ID_MARKER, ID_POLE, Walker
from gaitval.simulate.trialsim import POLE_RADIUS_M, TrialSim, _walls, preset_number

#: The turn marker 3 m from the chair's front edge on
#: the course axis: "walks three meters, turns around a marker, walks back to the chair and
#: sits down" (seed 000 §1; Podsiadlo & Richardson 1991: a line 3 m away).
TUG_MARKER_XY = (3.0, 0.0)
#: The marker's footprint the walker goes around (m: a cone's radius at shin height, as a
#: 45 cm traffic cone) and the clearance (m) its surface keeps from a shank's surface when
#: the inner foot swings past it.  The path uses this radius; what the *laser* sees of the
#: marker in its scan plane is the preset's ``tug.marker_scan_radius_m`` (default: this
#: radius), a separate setting because seed 000 gives no marker at all beyond "turns
#: around a marker" (docs/simulator.md, "Calibrated settings").
MARKER_RADIUS_M = 0.06
MARKER_CLEARANCE_M = 0.05
#: The chair's four legs (field frame, m; the front edge at x = 0) and their radius at
#: shin height (m), and the two calibration poles (seed 000 §2.2: "aligns the field and the
#: LRS using two poles"; positions not given, a free choice).
CHAIR_LEGS_XY = ((-0.02, 0.22), (-0.02, -0.22), (-0.42, 0.22), (-0.42, -0.22))
CHAIR_LEG_RADIUS_M = 0.015
TUG_POLES_XY = ((1.4, -1.0), (3.9, 1.3))
#: Where the turn to sit begins: the body is this far in front of its seated place.
TURN_TO_SIT_FROM_M = 0.45
#: Feet under the chair's front edge when seated (x), on the course axis (y = 0).
SEAT_X_M = 0.12
#: Half the distance between the feet when seated, at the start and again at the end (m):
#: seated people keep the feet about hip width apart.
SEATED_HALF_WIDTH_M = 0.10
#: Which way the participant turns to sit, seen from above: ``"left"`` (counter-clockwise,
#: the way the twin's walkers turn at the marker) or ``"right"``; no source says which,
#: so it is a free choice of the twin, the preset's ``tug.turn_to_sit`` (docs/simulator.md,
#: "Free choices of the twin"; the sensitivity preset ``tug_sit_turn_right``).
TURN_TO_SIT_DIRECTIONS = {"left": 2 * np.pi, "right": 0.0}     # heading when seated
#: Pivot steps of the turn to sit (180° in equal parts), the closing step not counted:
#: 60° per step, a turn without crossing the legs (docs/simulator.md); no source, so the
#: preset's ``tug.turn_to_sit_steps`` replaces it (docs/robustness.md: plausible 2-4).
TURN_TO_SIT_STEPS = 3
#: The capture ends this long after the participant is seated (s, uniform): the timed
#: span of the TUG ends when the participant sits (Podsiadlo & Richardson 1991).
END_AFTER_SEATED_S = (0.1, 0.3)
#: Step time of a turning step ÷ the walker's straight step time (issue 34).  On curved
#: paths people keep the stepping rate of straight walking and change speed through the
#: step length: Grasso R, Glasauer S, Takei Y, Berthoz A, "Gaze anticipation contributes
#: to steering in locomotion", doi:10.1201/9780203735701-41 (walking circular paths: "a high
#: correlation was found between linear speed and step-length while the correlation
#: between linear speed and stepping rate was much lower"; the main locomotion parameters
#: "fell in the range of those measured during linear walking"); Madrid J et al., Front
#: Hum Neurosci 2024;18:1269772 (10 young adults, 90 / 180 / 360° turns: cadence "a pace
#: gait constant").  Before issue 34 the TUG used ``GaitParams.turn_time_factor`` = 1.15,
#: which had no source.  Applies to the turn at the marker and to the pivot steps of the
#: turn to sit (turning steps of the same walker; no source gives those a step time).
#: A third source puts the factor a little above 1: on a figure-of-eight path at
#: self-selected speed all age groups walked ≈ 16 % slower than on a line and the two
#: younger groups (20–45, 46–65 years) took ≈ 8 % shorter steps (Front Neurol
#: 2021;12:698160, abstract), i.e. a cadence ≈ 9 % lower (step time ≈ 1.09 ×).  1.0 was
#: fixed before that source was read and before any simulation; the
#: ``tug_turn_step_time`` row's tolerance (±10 %) covers both readings.
TURN_TIME_FACTOR = 1.0


def turn_radius(gp, leg_width_m: float) -> float:
    """Radius of the body path around the marker: the tightest the participant's turning
    steps allow.

    No TUG paper gives the radius, so it follows from the geometry of the steps: in the turn
    the steps shorten to ``L_t = turn_step_factor · L`` (+ 2 SD of step variability; the
    factor 0.6 has no source: issue 34 looked for published step lengths of young adults
    in tight 180° turns and found none, docs/simulator.md), a
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


def turn_phase_bounds(walker: Walker, t_end: float, rate_hz: float, height_m: float
                      ) -> tuple[float, float]:
    """Start and end (s, mocap clock) of the TUG turning phase of a simulated trial.

    Seed 000 defines its three phases only in its Figure 3a ("three TUG phases (forward,
    turning and return phases) are defined"); its text places the turning phase where
    "the moving direction of the leg rapidly changes".  The twin uses the rule that labels
    the reproduced Table 4 (:func:`gaitval.evaluate.tug_truth.tug_phase_bounds`: the
    smoothed midpoint of the two legs at sensor height walks more than 30° off the
    outbound / return line), applied to the true legs at the mocap rate, so the twin's
    turning phase (``physics.csv``) and the tracked Table 4's count the same scans.  (The
    forward and return phases of the truth start with the rise and end seated, the TUG's
    span; the reproduced Table 4 counts from the first to the last truth sample, the
    still-seated spans of the capture included: docs/simulator.md.)
    """
    t = np.arange(0.0, t_end + 0.5 / rate_hz, 1.0 / rate_hz)
    legs = walker.legs(t)
    rows = [pd.DataFrame({"t_sensor_s": t, "side": side, "xs_m": p[:, 0], "ys_m": p[:, 1],
                          "valid": True})
            for side, p in (("L", legs[0].point_at_height(height_m)),
                            ("R", legs[1].point_at_height(height_m)))]
    b = tug_phase_bounds(pd.concat(rows, ignore_index=True))
    return float(b["t_turn_start_s"]), float(b["t_turn_end_s"])


def scene_circles(marker_scan_radius_m: float = MARKER_RADIUS_M) -> np.ndarray:
    """The TUG scene's static circles at shin height, ``(k, 4)``: ``x, y, radius, id``
    (field frame): the chair's legs, the turn marker and the calibration poles.

    ``marker_scan_radius_m`` is the marker's section in the scan plane (m); 0 leaves the
    marker out of the laser's scene (a marker lower than the scan plane, such as a line
    or a spot on the floor).
    """
    if not marker_scan_radius_m >= 0:
        raise ValueError(f"marker_scan_radius_m must be >= 0, got {marker_scan_radius_m!r}")
    circles = [(x, y, CHAIR_LEG_RADIUS_M, ID_CHAIR) for x, y in CHAIR_LEGS_XY]
    if marker_scan_radius_m > 0:
        circles.append((*TUG_MARKER_XY, float(marker_scan_radius_m), ID_MARKER))
    circles += [(x, y, POLE_RADIUS_M, ID_POLE) for x, y in TUG_POLES_XY]
    return np.array(circles, dtype=float)


def marker_scan_radius(cfg: dict) -> float:
    """The turn marker's section in the scan plane (m) of a preset's ``tug`` section
    (``marker_scan_radius_m``; default :data:`MARKER_RADIUS_M`)."""
    return float(cfg.get("marker_scan_radius_m", MARKER_RADIUS_M))


def _seated_heading(cfg: dict) -> float:
    """The heading (rad) the turn to sit ends at, from the preset's ``tug.turn_to_sit``
    (:data:`TURN_TO_SIT_DIRECTIONS`; the walker returns heading about π)."""
    from gaitval.errors import ConfigError

    way = cfg.get("turn_to_sit", "left")
    if way not in TURN_TO_SIT_DIRECTIONS:
        raise ConfigError(f"tug.turn_to_sit must be one of {sorted(TURN_TO_SIT_DIRECTIONS)}, "
                          f"got {way!r}", hint="the simulation preset's tug section")
    return TURN_TO_SIT_DIRECTIONS[way]


def _pivot_steps(cfg: dict) -> int:
    """The pivot steps of the turn to sit: the preset's ``tug.turn_to_sit_steps``, else
    :data:`TURN_TO_SIT_STEPS`."""
    return preset_number(cfg.get("turn_to_sit_steps", TURN_TO_SIT_STEPS),
                         "tug.turn_to_sit_steps", 2, 6, whole=True)


def build_tug(rng, study, subj, gp, trial, rep, sensor_pose, cfg) -> TrialSim:
    """Timed Up and Go: rise, walk 3 m, turn around a marker, walk back, turn, sit.

    Field frame: the chair's front edge at x = 0, facing +x; feet start at
    x = :data:`SEAT_X_M`.  The path (:func:`tug_path`) is out and back around the marker
    at (3, 0): out on the marker's right, a left turn of radius :func:`turn_radius`
    around it, back on the tangent towards the chair.  Where the return line ends
    (:data:`TURN_TO_SIT_FROM_M` before the seat) the participant turns to sit in
    :data:`TURN_TO_SIT_STEPS` (``tug.turn_to_sit_steps``) pivot steps without crossover
    that end at the seat facing +x, the other foot joins at hip width
    (:data:`SEATED_HALF_WIDTH_M`, as at the start), and they sit down: the descent starts
    as the last pivot step lands (the closing step is taken while lowering).
    """
    t_rise = float(rng.uniform(0.5, 0.9))
    rise_dur = float(rng.normal(0.9, 0.08))
    t0 = t_rise + 0.6 * rise_dur                       # gait initiation during the rise
    gp = replace(gp, turn_time_factor=TURN_TIME_FACTOR)
    path = tug_path(turn_radius(gp, subj["leg_width_m"]))
    plan = plan_steps(path, gp, rng, t0=t0, first_side=int(rng.integers(0, 2)),
                      end_pose=(SEAT_X_M, 0.0, _seated_heading(cfg), _pivot_steps(cfg)),
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
    poles = np.array(TUG_POLES_XY, dtype=float)
    # phases by the rule of the reproduced Table 4 (issue 34; before, the step labels:
    # lift-off of the first turning step, first contact on the return line, which
    # physics.step_label_bounds still reads from the events for its note)
    t_turn0, t_turn1 = turn_phase_bounds(walker, t_end, cfg["mocap_rate_hz"],
                                         cfg["sensor_height_m"])

    # the three phases partition the TUG itself, from the start of the rise to seated
    # (seed 000 §2.1 "three TUG phases"; §1 the TUG: "rises from a chair, ... walks back
    # to the chair and sits down"); the capture's still-seated spans before the rise and
    # after sitting are no TUG phase: "seated" (issue 34 follow-up, docs/simulator.md)
    t_seated = t_sit + sit_dur

    def phase(t):
        ph = np.where(t < t_turn0, "forward", np.where(t <= t_turn1, "turning", "return"))
        return np.where((t < t_rise) | (t > t_seated), "seated", ph).astype(object)

    return TrialSim(study=study, protocol="tug", subject=subj["subject"], trial=trial,
                    walker=walker, sensor="utm30lx", sensor_height_m=cfg["sensor_height_m"],
                    mocap_rate_hz=cfg["mocap_rate_hz"], t_end_s=t_end,
                    circles=scene_circles(marker_scan_radius(cfg)),
                    walls=_walls(-2.0, 5.5, -2.5, 2.5),
                    poles=poles, fixed_pose=sensor_pose, phase_fn=phase, repetition=rep,
                    speed="fast", variant={"t_phase": (t_turn0, t_turn1),
                                           "t_tug": (t_rise, t_seated)})
