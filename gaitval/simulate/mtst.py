"""The multi-target stepping task scene (seed 001): mat, coloured targets, attendant.

Every number here is a physical or anthropometric assumption documented in
``docs/simulator.md``; none is tuned towards a tracker's outcome.

References
----------
Yorozu A, Nishiguchi S, Yamada M, Aoyama T, Moriguchi T, Takahashi M. Gait measurement
system for the multi-target stepping task using a laser range sensor. Sensors
2015;15:11151–11168 (MTST: 5.85 × 1.15 m mat, 0.160 × 0.165 m targets, attendant,
Δt = 0.05 s, 16 elderly of whom 2 use a stick).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError
from gaitval.simulate.footsteps import first_swing_s
from gaitval.simulate.kinematics import (GaitParams, StepPlan, make_path, plan_from_footholds,
                                         plan_steps)
from gaitval.simulate.scene import ID_POLE, Walker
from gaitval.simulate.trialsim import POLE_RADIUS_M, TrialSim, _walls, preset_number

MAT_LENGTH, MAT_WIDTH = 5.85, 1.15
TARGET_W, TARGET_L = 0.160, 0.165
COLORS = ("red", "blue", "white")
#: calibration poles (field frame); in :func:`mtst_calibration` the one at the smaller beam
#: angle of the nominal sensor (beyond the goal, facing the walker) comes first.  Their
#: midpoint is 0.225 m off the walking line: with two poles the registration tells the pose
#: from its 180° turn about that midpoint by where the walker's legs land, and a midpoint
#: on the walking line maps the walk onto itself (issue 34: the first pole was at y = 1.35
#: m, midpoint y = 0.025 m, and one trial of the calibrated twin could not be told apart;
#: at y = 2.0 m, 0.2 m before the wall, the pole was not found in one participant's scans)
POLES_M = ((3.0, 1.75), (5.6, -1.3))
#: The nursing attendant's place (seed 001: "walked alongside the participant"; side and
#: distance are the twin's choice): side of the walker, distance from the mat's centreline
#: and how far behind the participant's start the attendant starts (m).
ATTENDANT_DEFAULT = {"side": "right", "lateral_m": 0.75, "behind_m": 0.25}
#: The target layout (seed 001: targets "arranged randomly" on the 1.15 m mat, no sizes):
#: the distance between rows is drawn uniform in ``row_spacing_m`` (m), the three lanes'
#: centres are at 0 and ± ``lane_m`` (m) from the centreline.  No source; the preset's
#: ``mtst.targets`` replaces them (docs/robustness.md: rows 0.8-1.6 m apart, lanes
#: ± 0.27-0.40 m; below 0.27 m two 0.16 m targets, each ± 0.05 m off its lane, can overlap).
TARGETS_DEFAULT = {"row_spacing_m": (1.0, 1.4), "lane_m": 0.35}
#: A participant with a stick (seed 001: 2 of the 16 use one; which hand and how far out
#: are not given): the hand and the stick's distance from the pelvis line (m); the preset's
#: ``mtst.stick`` replaces them (docs/robustness.md: either hand, 0.20-0.35 m).
STICK_DEFAULT = {"side": "right", "offset_m": 0.28}
#: where each trial's target layout is written, relative to the study folder
TARGETS_FILE = "targets/{trial}.targets.csv"


def mtst_calibration() -> dict:
    """The ``mtst:`` section of a simulated study's ``study.yaml``: what a lab measures once
    (target layout files, the mat's centreline and the pole centres in the field frame)."""
    return {"targets": TARGETS_FILE,
            "mat": {"start_m": [0.0, 0.0], "goal_m": [MAT_LENGTH, 0.0], "width_m": MAT_WIDTH},
            "poles_m": [list(p) for p in POLES_M]}


def _targets_cfg(cfg: dict | None) -> tuple[tuple[float, float], float]:
    """The row spacing range and lane offset of ``cfg["targets"]`` over
    :data:`TARGETS_DEFAULT`, checked (a :class:`~gaitval.errors.ConfigError` otherwise)."""
    t = {**TARGETS_DEFAULT, **((cfg or {}).get("targets") or {})}
    sp, lane = t["row_spacing_m"], t["lane_m"]
    ok_sp = (isinstance(sp, (list, tuple)) and len(sp) == 2
             and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in sp)
             and 0.5 <= sp[0] <= sp[1] <= 2.5)
    if not ok_sp:
        raise ConfigError(f"mtst.targets.row_spacing_m must be [low, high] in metres with "
                          f"0.5 <= low <= high <= 2.5, got {sp!r}",
                          hint="the simulation preset's mtst section")
    # below 0.27 m two 0.16 m targets, each 0.05 m off its lane, can overlap
    preset_number(lane, "mtst.targets.lane_m", 0.27, 0.45)
    return (float(sp[0]), float(sp[1])), float(lane)


def _stick_cfg(cfg: dict | None) -> tuple[int, float]:
    """The stick's hand (0 = left, 1 = right, as :class:`~gaitval.simulate.scene.Walker`)
    and its distance from the pelvis line (m): ``cfg["stick"]`` over :data:`STICK_DEFAULT`."""
    st = {**STICK_DEFAULT, **((cfg or {}).get("stick") or {})}
    off = st["offset_m"]
    if st["side"] not in ("right", "left"):
        raise ConfigError(f"mtst.stick.side must be 'right' or 'left', got {st['side']!r}",
                          hint="the simulation preset's mtst section")
    preset_number(off, "mtst.stick.offset_m", 0.1, 0.5)
    return (1 if st["side"] == "right" else 0), float(off)


def mtst_targets(rng, cfg: dict | None = None) -> pd.DataFrame:
    """Targets on the mat: rows every ≈ 1.0–1.4 m, three colours per row in random lanes.

    Lane centres at y = −0.35, 0, +0.35 m (the 1.15 m mat holds three 0.16 m targets with
    ≈ 0.19 m between them); a row's colours are a random permutation (the paper's
    "arranged randomly"), so the assigned colour jumps between lanes from row to row.
    ``cfg`` (the preset's ``mtst`` section) may replace the spacing and the lanes
    (``targets``, :data:`TARGETS_DEFAULT`).
    """
    (lo, hi), lane_m = _targets_cfg(cfg)
    rows = []
    x = 0.55
    tid = 0
    while x < MAT_LENGTH - 0.4:
        perm = rng.permutation(3)
        for lane, c in zip((-lane_m, 0.0, lane_m), perm):
            rows.append({"target": f"T{tid:02d}", "x_m": round(x, 3),
                         "y_m": round(lane + rng.uniform(-0.05, 0.05), 3), "color": COLORS[c]})
            tid += 1
        x += rng.uniform(lo, hi)
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
    The first step from standing follows the gait-initiation model of every protocol: its
    swing lasts a steady swing (:func:`~gaitval.simulate.footsteps.first_swing_s`) and, as
    a swing shorter than a stride, is a scaled copy of the steady one
    (:func:`~gaitval.simulate.kinematics.swing_scale`).
    """
    tg = targets[targets["color"] == color].sort_values("x_m").reset_index(drop=True)
    sides = [0, 1]
    xy = [np.array([-0.35, gp.step_width_m / 2]), np.array([-0.35, -gp.step_width_m / 2])]
    hd = [0.0, 0.0]
    lab = ["walk", "walk"]
    times, step_T = [], []          # contact increments; drawn step times (lift-offs)
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
        # gait initiation as in every protocol (footsteps.first_swing_s, docs/simulator.md):
        # the first swing from standing lasts a steady swing, (1 - stance_frac) 2 T
        times.append(first_swing_s(gp, T) if first else T)
        step_T.append(T)
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
                               np.array(lab, dtype=object), np.array(step_T), gp, t0)
    return plan, which


def build_mtst(rng, study, subj, gp, trial, rep, sensor_pose, cfg, color, stick,
               attendant_gp) -> TrialSim:
    """MTST trial: start → goal along the mat stepping on the assigned colour, attendant beside.

    The LRS stands where ``cfg["sensor_nominal_pose"]`` puts it (default preset: 1.0 m
    beyond the goal end of the mat facing the walker, x = 6.85 m, yaw = π).  The nursing
    attendant walks ``cfg["attendant"]`` (default: ``side: right``, ``lateral_m: 0.75``
    from the mat's centreline, ``behind_m: 0.25`` behind the participant's start) at the
    participant's speed.  Both are free choices of the twin (seed 001 states neither;
    ``docs/simulator.md``).
    """
    targets = mtst_targets(rng, cfg)
    t0 = float(rng.uniform(0.6, 1.0))
    plan, which = plan_mtst(rng, gp, targets, color, t0)
    hand, offset = _stick_cfg(cfg)
    walker = Walker(plan=plan, gp=gp, leg_width_m=subj["leg_width_m"],
                    sensor_height_m=cfg["sensor_height_m"],
                    stick_side=(hand if stick else None), stick_offset_m=offset)
    # attendant: same path shifted, own gait, same speed
    agp = attendant_gp
    dur = plan.t_end - t0
    n_att = max(2, int(round((MAT_LENGTH + 0.7) / agp.step_length_m)))
    agp = GaitParams(**{**agp.__dict__, "step_time_s": dur / (n_att + 1)})
    att = {**ATTENDANT_DEFAULT, **(cfg.get("attendant") or {})}
    if att["side"] not in ("right", "left"):
        raise ConfigError(f"mtst.attendant.side must be 'right' or 'left', got {att['side']!r}",
                          hint="config/studies/<preset>.yaml")
    ay = (-1.0 if att["side"] == "right" else 1.0) * float(att["lateral_m"])
    apath = make_path((-0.35 - float(att["behind_m"]), ay), 0.0,
                      [("line", MAT_LENGTH + 0.7, "walk")])
    aplan = plan_steps(apath, agp, rng, t0=t0 + 0.1, first_side=int(rng.integers(0, 2)))
    attendant = Walker(plan=aplan, gp=agp, leg_width_m=0.11,
                       sensor_height_m=cfg["sensor_height_m"])
    poles = np.array([POLES_M[1], POLES_M[0]])
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
