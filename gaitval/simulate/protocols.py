"""The three LRS protocols as scenes: subjects, paths, timing, fixed objects, sensor placement.

Each protocol has its own module — :mod:`gaitval.simulate.tug`,
:mod:`gaitval.simulate.mtst`, :mod:`gaitval.simulate.rollator` — built on
:class:`gaitval.simulate.trialsim.TrialSim`; this module draws the participants
(:func:`sample_subject`) and re-exports the protocols' public names.

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

import numpy as np

from gaitval.simulate.kinematics import GaitParams
from gaitval.simulate.mtst import (COLORS, MAT_LENGTH, MAT_WIDTH, TARGET_L, TARGET_W,
                                   build_mtst, mtst_targets, plan_mtst)
from gaitval.simulate.rollator import (RLT_CORNERS, RLT_HANDLE_M, RLT_TOP_M, build_rollator,
                                       rollator_path, rollator_tubes)
from gaitval.simulate.trialsim import POLE_RADIUS_M, POLE_TOP_M, TrialSim, _pose_jitter, _walls
from gaitval.simulate.tug import TUG_MARKER_XY, build_tug

__all__ = ["COLORS", "MAT_LENGTH", "MAT_WIDTH", "POLE_RADIUS_M", "POLE_TOP_M", "RLT_CORNERS",
           "RLT_HANDLE_M", "RLT_TOP_M", "TARGET_L", "TARGET_W", "TUG_MARKER_XY", "TrialSim",
           "_pose_jitter", "_walls", "build_mtst", "build_rollator", "build_tug",
           "mtst_targets", "plan_mtst", "rollator_path", "rollator_tubes", "sample_subject"]


def sample_subject(rng: np.random.Generator, group: str, sid: str, sensor_height: float,
                   stick: bool = False) -> tuple[dict, GaitParams]:
    """Anthropometrics (subject-table row) and gait parameters of one participant.

    Notes
    -----
    Segment proportions after Winter (2009): leg length 0.53 H, shank length 0.246 H.
    Shank width at the scan height includes clothing: ≈ 0.10 m at 0.27 m (seed 000 assumes
    w_l = 0.10 m) and wider at 0.40 m (calf).  Gait: young adults at maximum speed
    (TUG instruction) ≈ 1.7 m/s, step length ≈ 0.44 H, step time 0.45 s (≈ 133 /min, one
    between-subject SD below the walk–run transition cadence of ≈ 140 /min), stance ≈ 58 %;
    elderly: step 0.35 H and 0.536 s (112 /min), the centre of the older-adult range of
    Espy et al. 2010 Table 2 (0.297–0.403 H, 105–119 /min), wider and more variable steps
    (stance ≈ 63–65 %, CV 4–6 %); stick users 0.8 × the step and 1.2 × the step time;
    rollator patients slower still.  Both calibrations are checked in ``physics.csv``
    (docs/simulator.md, "Physical checks").
    """
    if group == "young":
        H = rng.normal(1.71, 0.06)
        age = rng.normal(23.0, 1.9)
        sl, st, sf, cv, sd, W = 0.44 * H, rng.normal(0.45, 0.02), 0.58, 0.025, 0.015, rng.normal(0.09, 0.015)
    elif group == "elderly":
        H = rng.normal(1.58, 0.07)
        age = rng.normal(78.1, 6.0)
        sl, st, sf, cv, sd, W = 0.35 * H, rng.normal(0.536, 0.04), 0.64, 0.045, 0.03, rng.normal(0.12, 0.02)
        if stick:
            sl, st, sf, W = 0.8 * sl, st * 1.2, 0.67, W + 0.02
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
