"""The three LRS protocols as scenes: subjects, paths, timing, fixed objects, sensor placement.

Every number here is a physical or anthropometric assumption documented in
``docs/simulator.md``; none is tuned towards a tracker's outcome.

References
----------
Yorozu A, Moriguchi T, Takahashi M. Improved leg tracking considering gait phase and
spline-based interpolation during turning motion in walk tests. Sensors 2015;15:22451–22472
(TUG: chair, 3 m, marker, two calibration poles, LRS at 0.27 m, 7 young adults × 4 trials).

Yorozu A, Nishiguchi S, Yamada M, Aoyama T, Moriguchi T, Takahashi M. Gait measurement
system for the multi-target stepping task using a laser range sensor. Sensors
2015;15:11151–11168 (MTST: 5.85 × 1.15 m mat, 0.160 × 0.165 m targets, attendant,
Δt = 0.05 s, 16 elderly of whom 2 use a stick).

Chalvatzaki G, Papageorgiou XS, Tzafestas CS, Maragos P. Comparative experimental
validation of human gait tracking algorithms for an intelligent robotic rollator. ICRA 2017
(UBG-04LX-F01 at ~0.40 m on the rollator facing the user; 2 scenarios × 2 repetitions).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import numpy as np
import pandas as pd

from gaitval.simulate.kinematics import (GaitParams, Path2D, StepPlan, make_path,
                                         plan_from_footholds, plan_steps)
from gaitval.simulate.scene import (ID_CHAIR, ID_MARKER, ID_OBSTACLE, ID_POLE, ID_ROLLATOR,
                                    Walker)

POLE_RADIUS_M = 0.025          # registration.pole_diameter_m default 0.05 m
POLE_TOP_M = 1.20


@dataclass
class TrialSim:
    """Everything needed to render one trial (field frame, mocap time)."""

    study: str
    protocol: str
    subject: str
    trial: str
    walker: Walker
    sensor: str
    sensor_height_m: float
    mocap_rate_hz: float
    t_end_s: float                              # mocap covers [0, t_end]
    circles: np.ndarray                         # (k, 4) cx, cy, r, id  (static, field)
    walls: np.ndarray                           # (m, 4) x0, y0, x1, y1 (field)
    poles: np.ndarray                           # (2, 2)
    fixed_pose: tuple | None                    # (x, y, yaw) of a fixed sensor
    rollator: Callable | None = None            # t -> (n, 3) rollator pose (field)
    sensor_mount: tuple | None = None           # sensor pose in the rollator frame
    attendant: Walker | None = None
    phase_fn: Callable | None = None            # t -> array of phase names
    targets: pd.DataFrame | None = None         # MTST targets (x_m, y_m, color, assigned)
    target_steps: dict = field(default_factory=dict)   # contact index -> target id
    log_every: int = 1                          # keep every n-th scan (MTST Δt = 0.05 s)
    scenario: str = ""
    repetition: int = 1
    speed: str = ""
    stick: bool = False
    variant: dict = field(default_factory=dict)


# --------------------------------------------------------------------------- subjects
def sample_subject(rng: np.random.Generator, group: str, sid: str, sensor_height: float,
                   stick: bool = False) -> tuple[dict, GaitParams]:
    """Anthropometrics (subject-table row) and gait parameters of one participant.

    Notes
    -----
    Segment proportions after Winter (2009): leg length 0.53 H, shank length 0.246 H.
    Shank width at the scan height includes clothing: ≈ 0.10 m at 0.27 m (seed 000 assumes
    w_l = 0.10 m) and wider at 0.40 m (calf).  Gait: young adults at maximum speed
    (TUG instruction) ≈ 1.7 m/s, step length ≈ 0.44 H, cadence ≈ 140 /min, stance ≈ 58 %;
    elderly slower, shorter, wider and more variable steps (stance ≈ 63–65 %,
    CV 4–6 %); stick users and rollator patients slower still.
    """
    if group == "young":
        H = rng.normal(1.71, 0.06)
        age = rng.normal(23.0, 1.9)
        sl, st, sf, cv, sd, W = 0.44 * H, rng.normal(0.42, 0.02), 0.58, 0.025, 0.015, rng.normal(0.09, 0.015)
    elif group == "elderly":
        H = rng.normal(1.58, 0.07)
        age = rng.normal(78.1, 6.0)
        sl, st, sf, cv, sd, W = 0.31 * H, rng.normal(0.56, 0.04), 0.64, 0.045, 0.03, rng.normal(0.12, 0.02)
        if stick:
            sl, st, sf, W = 0.25 * H, st * 1.2, 0.67, W + 0.02
    elif group == "patient":
        H = rng.normal(1.62, 0.07)
        age = rng.normal(80.0, 5.0)
        sl, st, sf, cv, sd, W = 0.24 * H, rng.normal(0.62, 0.05), 0.66, 0.06, 0.03, rng.normal(0.14, 0.02)
    else:
        H = rng.normal(1.74, 0.07)
        age = rng.normal(30.0, 6.0)
        sl, st, sf, cv, sd, W = 0.40 * H, rng.normal(0.52, 0.03), 0.60, 0.025, 0.015, rng.normal(0.10, 0.015)
    W = float(np.clip(W, 0.05, 0.2))
    base_w = 0.100 if sensor_height < 0.33 else 0.118
    leg_w = float(np.clip(rng.normal(base_w, 0.008), 0.08, 0.14))
    subj = {
        "subject": sid, "group": group, "age_y": round(float(age), 1),
        "sex": str(rng.choice(["M", "F"], p=[0.7, 0.3])),
        "height_m": round(float(H), 3), "mass_kg": round(float(rng.normal(22.5, 2.0) * H * H), 1),
        "leg_width_m": round(leg_w, 4),
        "knee_width_m": round(float(rng.normal(0.100, 0.006)), 4),
        "ankle_width_m": round(float(rng.normal(0.070, 0.004)), 4),
        "leg_length_m": round(0.53 * float(H), 3),
        "shank_length_m": round(0.246 * float(H), 3), "stick": bool(stick),
    }
    gp = GaitParams(step_length_m=float(sl), step_width_m=W, step_time_s=float(st),
                    stance_frac=sf, step_cv=cv, place_sd_m=sd,
                    shank_length_m=0.246 * H - 0.0, ankle_height_m=0.039 * H,
                    hip_height_m=0.53 * H - 0.04,
                    # the foot rolls over the forefoot before toe off: ankle joint centre
                    # ≈ 0.085 H behind the metatarsal heads; real walks (docs/simulator.md)
                    # show it ≈ 0.14 m further forward and ≈ 0.10 m higher at toe off
                    roll_fwd_m=0.085 * H, roll_up_m=0.06 * H)
    return subj, gp


def _walls(x0, x1, y0, y1) -> np.ndarray:
    return np.array([[x0, y0, x1, y0], [x1, y0, x1, y1], [x1, y1, x0, y1], [x0, y1, x0, y0]])


def _pose_jitter(rng, nominal, sd_xy=0.05, sd_yaw_deg=3.0) -> tuple:
    return (float(nominal[0] + sd_xy * rng.standard_normal()),
            float(nominal[1] + sd_xy * rng.standard_normal()),
            float(nominal[2] + np.deg2rad(sd_yaw_deg) * rng.standard_normal()))


def _phase_from_plan(plan: StepPlan, labels_by_contact: np.ndarray, t_lo: float):
    """t -> phase name: the label of the next contact (phase changes at foot contacts)."""
    tc = plan.t_contact.copy()
    lab = np.asarray(labels_by_contact, dtype=object)

    def fn(t):
        i = np.searchsorted(tc, t, side="left")
        i = np.clip(i, 2, len(tc) - 1)
        return lab[i]
    return fn


# --------------------------------------------------------------------------- TUG
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


# --------------------------------------------------------------------------- MTST
MAT_LENGTH, MAT_WIDTH = 5.85, 1.15
TARGET_W, TARGET_L = 0.160, 0.165
COLORS = ("red", "blue", "white")


def mtst_targets(rng) -> pd.DataFrame:
    """Targets on the mat: rows every ≈ 0.45–0.6 m, three colours per row in random lanes.

    Lane centres at y = −0.35, 0, +0.35 m (the 1.15 m mat holds three 0.16 m targets with
    ≈ 0.19 m between them); a row's colours are a random permutation (the paper's
    "arranged randomly"), so the assigned colour jumps between lanes from row to row.
    """
    rows = []
    x = 0.55
    tid = 0
    while x < MAT_LENGTH - 0.4:
        perm = rng.permutation(3)
        for lane, c in zip((-0.35, 0.0, 0.35), perm):
            rows.append({"target": f"T{tid:02d}", "x_m": round(x, 3),
                         "y_m": round(lane + rng.uniform(-0.05, 0.05), 3), "color": COLORS[c]})
            tid += 1
        x += rng.uniform(1.0, 1.4)
    return pd.DataFrame(rows)


def plan_mtst(rng, gp: GaitParams, targets: pd.DataFrame, color: str, t0: float
              ) -> tuple[StepPlan, dict]:
    """Footholds from start to goal stepping on every target of ``color``.

    Walkers take nominal steps along y = 0 and, before each assigned target, choose the
    number of steps (nominal count ± 2, step length within 0.6–1.35 of nominal) that
    brings the foot on the target's side onto it; when no count fits (targets too close),
    the foot that arrives takes the target even across the midline — a cross step
    arises from the geometry.  Placement scatter is ``place_sd_m`` around the aim, plus
    for target steps 2 cm and 10 % of the distance between the target and the foothold
    the walker would have chosen without it (endpoint error grows with the correction).
    """
    tg = targets[targets["color"] == color].sort_values("x_m").reset_index(drop=True)
    sides = [0, 1]
    xy = [np.array([-0.35, gp.step_width_m / 2]), np.array([-0.35, -gp.step_width_m / 2])]
    hd = [0.0, 0.0]
    lab = ["walk", "walk"]
    times = []
    which: dict[int, str] = {}
    side = int(rng.integers(0, 2))
    x = -0.35
    L0 = gp.step_length_m
    goal = MAT_LENGTH + 0.35

    def add(aim, label, first=False, extra_sd=0.0):
        nonlocal side, x
        p = np.asarray(aim, float) + np.hypot(gp.place_sd_m, extra_sd) * rng.standard_normal(2)
        T = gp.step_time_s * (1 + gp.step_cv * rng.standard_normal())
        sides.append(side)
        xy.append(p)
        hd.append(float(0.04 * rng.standard_normal()))
        lab.append(label)
        times.append(T * (0.9 if first else 1.0))
        side = 1 - side
        x = float(aim[0])

    def own_side():
        """A free step lands on its own side of the walkway centre and at least half a
        step width to its own side of the stance foot (so a cross step is undone)."""
        W = gp.step_width_m
        y_st = xy[-1][1]
        return max(W / 2, y_st + W / 2) if side == 0 else min(-W / 2, y_st - W / 2)

    nstep = 0
    for _, row in tg.iterrows():
        d = row["x_m"] - x
        want = 0 if row["y_m"] > 0.05 else (1 if row["y_m"] < -0.05 else None)
        best = None
        for n in sorted({max(1, int(round(d / L0)) + k) for k in (-2, -1, 0, 1, 2)}):
            ratio = d / n / L0
            if not 0.6 <= ratio <= 1.35:
                continue
            arriving = side if n % 2 == 1 else 1 - side
            ok = want is None or arriving == want
            cost = abs(ratio - 1) + (0 if ok else 10)
            if best is None or cost < best[0]:
                best = (cost, n)
        n = best[1] if best else max(1, int(round(d / L0)))
        for k in range(1, n):
            add((x + d / n, own_side()), "walk", nstep == 0)
            nstep += 1
        which[len(sides)] = row["target"]
        # endpoint scatter grows with the adjustment away from the natural foothold
        # (Fitts-like: SD ≈ 10 % of the corrective movement's amplitude)
        natural = np.array([x + d / n, own_side()])
        amp = float(np.hypot(*(np.array([row["x_m"], row["y_m"]]) - natural)))
        add((row["x_m"], row["y_m"]), "target", nstep == 0, extra_sd=0.10 * amp + 0.02)
        nstep += 1
    while goal - x > 0.3 * L0:
        d = goal - x
        n = max(1, int(np.ceil(d / L0)))
        add((x + d / n, own_side()), "walk", nstep == 0)
        nstep += 1
    # closing step beside the last foot
    add((x, own_side()), "walk")
    plan = plan_from_footholds(np.array(sides), t0 + np.concatenate([[-np.inf, -np.inf],
                               np.cumsum(times)]), np.array(xy), np.array(hd),
                               np.array(lab, dtype=object), np.array(times), gp, t0)
    return plan, which


def build_mtst(rng, study, subj, gp, trial, rep, sensor_pose, cfg, color, stick,
               attendant_gp) -> TrialSim:
    """MTST trial: start → goal along the mat stepping on the assigned colour, attendant beside.

    The LRS stands 1.0 m beyond the goal end of the mat facing the walker (x = 6.85 m,
    yaw = π nominal).  The nursing attendant walks 0.75 m to the participant's right,
    0.25 m behind, at the participant's speed.
    """
    targets = mtst_targets(rng)
    t0 = float(rng.uniform(0.6, 1.0))
    plan, which = plan_mtst(rng, gp, targets, color, t0)
    walker = Walker(plan=plan, gp=gp, leg_width_m=subj["leg_width_m"],
                    stick_side=(1 if stick else None))
    # attendant: same path shifted, own gait, same speed
    agp = attendant_gp
    dur = plan.t_end - t0
    n_att = max(2, int(round((MAT_LENGTH + 0.7) / agp.step_length_m)))
    agp = GaitParams(**{**agp.__dict__, "step_time_s": dur / (n_att + 1)})
    apath = make_path((-0.6, -0.75), 0.0, [("line", MAT_LENGTH + 0.7, "walk")])
    aplan = plan_steps(apath, agp, rng, t0=t0 + 0.1, first_side=int(rng.integers(0, 2)))
    attendant = Walker(plan=aplan, gp=agp, leg_width_m=0.11)
    poles = np.array([[5.6, -1.3], [3.0, 1.35]])
    circles = [(x, y, POLE_RADIUS_M, ID_POLE) for x, y in poles]
    t_end = plan.t_end + float(rng.uniform(0.8, 1.2))
    targets = targets.assign(assigned=targets["color"] == color)
    return TrialSim(study=study, protocol="mtst", subject=subj["subject"], trial=trial,
                    walker=walker, sensor="utm30lx", sensor_height_m=cfg["sensor_height_m"],
                    mocap_rate_hz=cfg["mocap_rate_hz"], t_end_s=t_end,
                    circles=np.array(circles, dtype=float), walls=_walls(-2.0, 8.5, -2.2, 2.2),
                    poles=poles, fixed_pose=sensor_pose, attendant=attendant,
                    phase_fn=lambda t: np.full(len(t), "walk", dtype=object),
                    targets=targets, target_steps=which,
                    log_every=int(round(cfg["log_period_s"] / 0.025)), repetition=rep,
                    stick=stick, scenario=color, variant={})


# --------------------------------------------------------------------------- rollator
RLT_CORNERS = {"RLT_FL": (0.30, 0.28), "RLT_FR": (0.30, -0.28),
               "RLT_RL": (-0.30, 0.28), "RLT_RR": (-0.30, -0.28)}
RLT_TOP_M = 0.85
RLT_HANDLE_M = 0.62          # pelvis → rollator centre


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
    walker = Walker(plan=plan, gp=gp, leg_width_m=subj["leg_width_m"])
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
