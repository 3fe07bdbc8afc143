"""The rollator scene (Chalvatzaki et al. 2017): paths, the rollator and its sensor.

Every number here is a physical or anthropometric assumption documented in
``docs/simulator.md``; none is tuned towards a tracker's outcome.

References
----------
Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental
validation of human gait tracking algorithms for an intelligent robotic rollator. ICRA 2017
(UBG-04LX-F01 at ~0.40 m on the rollator facing the user; 2 scenarios × 2 repetitions).
"""
from __future__ import annotations

import numpy as np

from gaitval.simulate.kinematics import Path2D, StepPlan, make_path, plan_steps
from gaitval.simulate.scene import ID_OBSTACLE, ID_POLE, ID_ROLLATOR, Walker
from gaitval.simulate.trialsim import POLE_RADIUS_M, TrialSim, _walls

RLT_CORNERS = {"RLT_FL": (0.30, 0.28), "RLT_FR": (0.30, -0.28),
               "RLT_RL": (-0.30, 0.28), "RLT_RR": (-0.30, -0.28)}
RLT_TOP_M = 0.85
RLT_HANDLE_M = 0.62          # pelvis → rollator centre


def _phase_from_plan(plan: StepPlan, labels_by_contact: np.ndarray, t_lo: float):
    """t -> phase name: the label of the next contact (phase changes at foot contacts)."""
    tc = plan.t_contact.copy()
    lab = np.asarray(labels_by_contact, dtype=object)

    def fn(t):
        i = np.searchsorted(tc, t, side="left")
        i = np.clip(i, 2, len(tc) - 1)
        return lab[i]
    return fn


def rollator_path(scenario: str) -> Path2D:
    if scenario == "straight":
        return make_path((0.0, 0.0), 0.0, [("line", 3.0, "forward"),
                                             ("arc", 0.6, np.pi, "turning"),
                                             ("line", 3.0, "return")])
    a = np.deg2rad(35.0)
    return make_path((0.0, 0.0), 0.0, [("line", 1.0, "forward"),
                                         ("arc", 1.0, a, "manoeuvre"), ("arc", 1.0, -2 * a, "manoeuvre"),
                                         ("arc", 1.0, a, "manoeuvre"), ("line", 0.6, "forward"),
                                         ("arc", 1.0, -a, "manoeuvre"), ("arc", 1.0, 2 * a, "manoeuvre"),
                                         ("arc", 1.0, -a, "manoeuvre"), ("line", 1.0, "forward")])


def build_rollator(rng, study, subj, gp, trial, rep, scenario, cfg) -> TrialSim:
    """Rollator trial: the user walks the path, the rollator 0.62 m ahead, sensor facing back.

    The rollator frame's pose follows the user's pelvis (hands on the handles): centre
    ``pelvis + R(ψ)[0.62, 0]`` with the pelvis heading ψ smoothed over a stride.  The
    LRS sits on the rear cross-bar at ``sensor_mount`` (default x = −0.22 m, y = 0,
    yaw = π: facing the user) at 0.40 m; the two rear frame tubes (radius 0.0125 m) are
    in its 240° field of view.
    """
    path = rollator_path(scenario)
    t0 = float(rng.uniform(0.8, 1.2))
    plan = plan_steps(path, gp, rng, t0=t0, first_side=int(rng.integers(0, 2)))
    walker = Walker(plan=plan, gp=gp, leg_width_m=subj["leg_width_m"],
                    sensor_height_m=cfg["sensor_height_m"])
    sway = rng.normal(0, 0.01)

    def rpose(t):
        p, hd = walker.pelvis(t)
        c = p[:, :2] + RLT_HANDLE_M * np.column_stack([np.cos(hd), np.sin(hd)])
        c[:, 1] += sway * np.sin(2 * np.pi * t / (2 * gp.step_time_s))
        return np.column_stack([c, hd])

    m = cfg.get("sensor_mount") or {"x_m": -0.22, "y_m": 0.0, "yaw_rad": np.pi}
    mount = (float(m["x_m"]), float(m["y_m"]), float(m["yaw_rad"]))
    obstacles = []
    if scenario != "straight":
        obstacles = [(2.05, -0.15, 0.20, ID_OBSTACLE), (4.3, 0.55, 0.20, ID_OBSTACLE)]
    poles = np.array([[-1.0, -1.5], [5.5, 1.8]])
    circles = [(x, y, POLE_RADIUS_M, ID_POLE) for x, y in poles] + obstacles
    labs = plan.label
    phase = _phase_from_plan(plan, labs, 0.0)
    return TrialSim(study=study, protocol="rollator", subject=subj["subject"], trial=trial,
                    walker=walker, sensor="ubg04lx", sensor_height_m=cfg["sensor_height_m"],
                    mocap_rate_hz=cfg["mocap_rate_hz"], t_end_s=plan.t_end + 0.8,
                    circles=np.array(circles, dtype=float), walls=_walls(-2.0, 6.5, -2.2, 3.2),
                    poles=poles, fixed_pose=None, rollator=rpose, sensor_mount=mount,
                    phase_fn=phase, scenario=scenario, repetition=rep, variant={})


def rollator_tubes(pose: np.ndarray) -> np.ndarray:
    """(n, 2, 4) the two rear frame tubes (cx, cy, r, id) in the field frame."""
    out = np.empty((len(pose), 2, 4))
    for k, (x, y) in enumerate([RLT_CORNERS["RLT_RL"], RLT_CORNERS["RLT_RR"]]):
        c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
        out[:, k, 0] = pose[:, 0] + c * x - s * y
        out[:, k, 1] = pose[:, 1] + s * x + c * y
        out[:, k, 2] = 0.0125
        out[:, k, 3] = ID_ROLLATOR
    return out
