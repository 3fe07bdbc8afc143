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

TUG_MARKER_XY = (3.0, 0.45)


def build_tug(rng, study, subj, gp, trial, rep, sensor_pose, cfg) -> TrialSim:
    """Timed Up and Go: rise, walk 3 m, turn around a marker, walk back, turn, sit.

    Field frame: the chair's front edge at x = 0, facing +x; feet start at x = 0.12.
    The path goes along y = 0 to x = 3.0, turns left around the marker (a cone,
    0.06 m radius at shin height) at (3.0, 0.45) on a 0.45 m radius (body centre line:
    the trunk's half width ≈ 0.2 m plus clearance from the cone), comes back along
    y = 0.90, turns left again by 180° on a 0.45 m radius in front of the chair (the turn
    to sit) and ends with a small backward step to the seat before sitting down.
    """
    t_rise = float(rng.uniform(0.5, 0.9))
    rise_dur = float(rng.normal(0.9, 0.08))
    t0 = t_rise + 0.6 * rise_dur                       # gait initiation during the rise
    r_turn = TUG_MARKER_XY[1]
    r_sit = r_turn
    path = make_path((0.12, 0.0), 0.0, [("line", TUG_MARKER_XY[0] - 0.12, "forward"),
                                         ("arc", r_turn, np.pi, "turning"),
                                         ("line", TUG_MARKER_XY[0] - 0.50, "return"),
                                         ("arc", r_sit, np.pi, "return")])
    # after the turn to sit the walker stands 0.38 m in front of the seat: one small
    # backward step to the chair, then the other foot joins
    plan = plan_steps(path, gp, rng, t0=t0, first_side=int(rng.integers(0, 2)),
                      end_pose=(0.12, 0.0, 2 * np.pi, 1), start_half_width=0.10)
    t_sit = plan.t_end + 0.15
    sit_dur = float(rng.normal(1.0, 0.08))
    t_end = t_sit + sit_dur + float(rng.uniform(0.4, 0.7))

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
                    posture_tilt=ptilt)
    chair = [(-0.02, 0.22), (-0.02, -0.22), (-0.42, 0.22), (-0.42, -0.22)]
    circles = [(x, y, 0.015, ID_CHAIR) for x, y in chair]
    circles.append((*TUG_MARKER_XY, 0.06, ID_MARKER))
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
