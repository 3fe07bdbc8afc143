"""MTST walking parameters from a two-leg track (seed 001 §2.5): foot contacts, target-step
judgement and cross-step detection.

Inputs are plain arrays or the tidy track table of :func:`gaitval.methods.track_trial`
(one row per scan and side: ``k, t_sensor_s, side, x_m, y_m, vx_mps, vy_mps, swing, ...``);
positions may be in any planar frame as long as the targets, the walking direction and the
contacts share it (the pipeline uses the field frame, :mod:`gaitval.pipeline.mtst`).

Foot contact (§2.5.1)
    "the foot contact time is extracted as the time when the leg speed is at a minimum value
    in the stance phase", the position being the shin estimate then.  A stance phase is a
    run of scans the tracker's gait-phase rule (seed001 eq. (9)–(10)) calls stance.  Runs
    shorter than ``min_stance_s`` are not stances and swing runs shorter than
    ``min_swing_s`` do not split a stance (0.10 s each, two scans at Δt = 0.05 s: a single
    scan on the wrong side of a speed threshold is noise of the rule, while an elderly
    participant's stance lasts ≈ 0.7 s and swing ≈ 0.4 s).  The stance a leg is in when
    its track starts (the participant standing at the start) is not a contact: a contact
    ends a swing.
Target-step judgement (§2.5.2, Fig. 6)
    A contact is on an assigned target when its position lies in the target's judgement
    region.  The paper builds the region (Fig. 6c) from a leg model (Fig. 6b) whose
    numbers it does not print (GAP).  gaitval's region is the set of shin positions for
    which an average foot overlaps the target: at the contact the shank is vertical (§2.5.1),
    so the shin point is above the ankle; the foot reaches ``toe = (1 − heel_frac)·L_f``
    ahead of the ankle and ``heel = heel_frac·L_f`` behind it and is ``W_f`` wide, with
    L_f = 0.152 H and W_f = 0.055 H (H the participant's height; Winter, Biomechanics and
    Motor Control of Human Movement, 4th ed., Fig. 4.1) and heel_frac = 0.25 (the ankle
    joint a quarter of the foot length in front of the heel; an anthropometric
    approximation, GAP).  A foot overlaps a target of length L_t (along the walk) and width
    W_t when the ankle lies in
    −(L_t/2 + toe) ≤ a ≤ L_t/2 + heel,  |l| ≤ (W_t + W_f)/2,
    with a, l the ankle's coordinates along and across the walking direction from the
    target's centre.  Nothing in it comes from tracking results.
Cross step (§2.5.3, eq. (11))
    At each contact of the swinging leg: an x′–y′ frame with its origin at that leg's
    previous contact and x′ along the walking direction.  With p′_st the supporting leg's
    contact during that swing and p′_sw(k) the swinging leg's positions in its swing phase,
    cross ⇔ y′_st < w_c ∧ ∃k: y′_sw(k) < −w_c,   w_c = w_l/2.
    The paper states it for the right leg swinging ("right leg in this case") and "for
    the left leg in the same way"; the orientation of y′ is in its Figure 7 only (GAP).
    gaitval takes the ordinary right-handed frame of that example — x′ forward, y′ to the
    left, i.e. towards the supporting leg — mirrored for the left leg
    (``y_towards="support_side"``).  The rule then reads: the supporting foot was placed
    not clearly on its own side of the swinging leg (in line with it or across it,
    y′_st < w_c), and the swinging leg goes round it, more than w_c towards its own side.
    That is the swing that follows a foot placed across the other's line, so the episode a
    rater marks at the crossing foot's contact is detected at the next contact, of the
    other leg (:mod:`gaitval.evaluate.mtst` matches the two).  The mirrored frame
    (``"swing_side"``: y′ towards the swinging leg's own side) would flag the crossing
    swing itself, but also every swing that moves more than w_c back towards the midline —
    which on a mat with targets in three lanes happens after most side-lane targets, so it
    cannot give the paper's 0 false detections in 15 (Table 4); it is kept as an option.

References
----------
Yorozu, A.; Nishiguchi, S.; Yamada, M.; Aoyama, T.; Moriguchi, T.; Takahashi, M. Gait
Measurement System for the Multi-Target Stepping Task Using a Laser Range Sensor. Sensors
2015, 15, 11151–11168 (seed 001), §2.5.
Winter, D.A. Biomechanics and Motor Control of Human Movement, 4th ed.; Wiley: Hoboken,
NJ, 2009; Figure 4.1 (segment lengths as fractions of body height).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from gaitval.errors import ConfigError

CONTACT_COLUMNS = ("side", "k", "t_sensor_s", "x_m", "y_m", "speed_mps", "k_stance_start",
                   "k_stance_end")


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) index pairs of the True runs of a boolean array."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    return list(zip(np.flatnonzero(d == 1).tolist(), np.flatnonzero(d == -1).tolist()))


def stance_runs(swing: np.ndarray, tracked: np.ndarray, n_stance: int, n_swing: int
                ) -> list[tuple[int, int]]:
    """Stance phases of one leg as (start, stop) index pairs (module notes).

    Parameters
    ----------
    swing, tracked : ndarray of bool
        Per scan: the leg swings (tracker's phase); the track exists.
    n_stance, n_swing : int
        Shortest stance run kept; shortest swing run that separates two stances.
    """
    st = ~np.asarray(swing, bool) & np.asarray(tracked, bool)
    runs = _runs(st)
    merged: list[list[int]] = []
    for a, b in runs:
        if merged and a - merged[-1][1] < n_swing and tracked[merged[-1][1]:a].all():
            merged[-1][1] = b                       # a swing flicker does not end a stance
        else:
            merged.append([a, b])
    return [(a, b) for a, b in merged if b - a >= n_stance]


def foot_contacts(track: pd.DataFrame, *, min_stance_s: float = 0.10,
                  min_swing_s: float = 0.10) -> pd.DataFrame:
    """Foot contacts of both legs (§2.5.1): the minimum-speed scan of every stance that
    follows a swing.

    Parameters
    ----------
    track : DataFrame
        Tidy track (``k, t_sensor_s, side, x_m, y_m, vx_mps, vy_mps, swing``).
    min_stance_s, min_swing_s : float
        Shortest stance kept and shortest swing that separates two stances (s).

    Returns
    -------
    DataFrame
        :data:`CONTACT_COLUMNS`, sorted by time: the contact scan ``k``, its time, the leg
        position then (same frame as the track), the leg speed there and the stance run.
    """
    rows = []
    for side in ("L", "R"):
        d = track[track["side"] == side].sort_values("k")
        t = d["t_sensor_s"].to_numpy(float)
        if len(t) < 2:
            continue
        dt = float(np.median(np.diff(t)))
        x, y = d["x_m"].to_numpy(float), d["y_m"].to_numpy(float)
        sp = np.hypot(d["vx_mps"].to_numpy(float), d["vy_mps"].to_numpy(float))
        tracked = np.isfinite(x) & np.isfinite(sp)
        swing = d["swing"].to_numpy(bool)
        runs = stance_runs(swing, tracked, max(1, math.ceil(min_stance_s / dt - 1e-9)),
                           max(1, math.ceil(min_swing_s / dt - 1e-9)))
        k = d["k"].to_numpy(int)
        first = int(np.argmax(tracked)) if tracked.any() else len(t)
        for a, b in runs:
            if a <= first or not swing[first:a].any():
                continue                            # standing at the start: no contact
            i = a + int(np.argmin(sp[a:b]))         # §2.5.1: minimum leg speed in stance
            rows.append((side, int(k[i]), float(t[i]), float(x[i]), float(y[i]),
                         float(sp[i]), int(k[a]), int(k[b - 1])))
    out = pd.DataFrame(rows, columns=list(CONTACT_COLUMNS))
    return out.sort_values(["t_sensor_s", "side"], kind="stable").reset_index(drop=True)


@dataclass(frozen=True)
class FootModel:
    """The average foot of the judgement region (module notes), metres.

    Build it with :meth:`for_height`; ``toe`` and ``heel`` are the foot's reach ahead of
    and behind the ankle, ``width`` its breadth.
    """

    toe: float
    heel: float
    width: float

    @classmethod
    def for_height(cls, height_m: float, length_per_height: float = 0.152,
                   width_per_height: float = 0.055, heel_per_length: float = 0.25
                   ) -> "FootModel":
        """Foot of a participant of height ``height_m`` (Winter Fig. 4.1 proportions)."""
        L = length_per_height * height_m
        return cls(toe=(1.0 - heel_per_length) * L, heel=heel_per_length * L,
                   width=width_per_height * height_m)


def judgement_region(foot: FootModel, target_size_m: tuple[float, float]
                     ) -> tuple[float, float, float]:
    """``(a_min, a_max, l_half)``: the region around a target's centre where a contact is
    judged on it, along (a) and across (l) the walking direction (module notes)."""
    L_t, W_t = target_size_m
    return -(L_t / 2 + foot.toe), L_t / 2 + foot.heel, (W_t + foot.width) / 2


def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    n = float(np.hypot(v[0], v[1]))
    if n <= 0:
        raise ConfigError("the MTST walking direction has zero length (mtst.mat start_m and "
                          "goal_m coincide)")
    return v / n


def judge_target_steps(xy: np.ndarray, targets: pd.DataFrame, region, heading
                       ) -> np.ndarray:
    """Target of each contact (§2.5.2): the id of the assigned target whose judgement
    region holds the contact (the nearest if several), ``""`` for none.

    Parameters
    ----------
    xy : ndarray (n, 2)
        Contact positions.
    targets : DataFrame
        ``target, x_m, y_m, assigned`` (only assigned targets are judged).
    region : (a_min, a_max, l_half)
        From :func:`judgement_region`.
    heading : (2,)
        The walking direction (start → goal).
    """
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    u = _unit(heading)
    n = np.array([-u[1], u[0]])
    tg = targets[targets["assigned"].astype(bool)]
    c = tg[["x_m", "y_m"]].to_numpy(float)
    ids = tg["target"].astype(str).to_numpy()
    out = np.full(len(xy), "", dtype=object)
    if len(c) == 0:
        return out
    a_min, a_max, l_half = region
    d = xy[:, None, :] - c[None, :, :]
    a = d @ u
    lat = d @ n
    inside = (a >= a_min) & (a <= a_max) & (np.abs(lat) <= l_half)   # §2.5.2, Fig. 6c
    dist = np.where(inside, np.hypot(a, lat), np.inf)
    hit = inside.any(axis=1)
    out[hit] = ids[np.argmin(dist[hit], axis=1)]
    return out


def _leg_samples(g: pd.DataFrame) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One leg's track as (scan index k ascending, (n, 2) positions, swing flags)."""
    g = g.sort_values("k", kind="stable")
    return (g["k"].to_numpy(), g[["x_m", "y_m"]].to_numpy(float),
            g["swing"].astype(bool).to_numpy())


def cross_steps(contacts: pd.DataFrame, track: pd.DataFrame, heading, w_c: float,
                y_towards: str = "support_side") -> np.ndarray:
    """Cross-step flag of each contact (eq. (11), orientation in the module notes).

    Parameters
    ----------
    contacts : DataFrame
        :func:`foot_contacts` output (``side, k, x_m, y_m``), same frame as ``track``.
    track : DataFrame
        The track (``k, side, x_m, y_m, swing``).
    heading : (2,)
        The walking direction.
    w_c : float
        Threshold, w_l/2 (seed 001 §2.5.3).
    y_towards : {"support_side", "swing_side"}
        Orientation of y′: towards the supporting leg's side (the right-handed frame of the
        paper's right-leg example; gaitval's reading, module notes) or towards the swinging
        leg's own side (the other reading, for comparison).

    Returns
    -------
    ndarray of bool, aligned with ``contacts`` rows: the contact ends a swing that was a
    cross step.  A contact whose leg has no previous contact, or with no contact of the
    other leg in between, is never flagged (eq. (11) cannot be evaluated).
    """
    if y_towards not in ("swing_side", "support_side"):
        raise ConfigError(f"mtst.cross.y_towards must be swing_side or support_side, not "
                          f"{y_towards!r}")
    u = _unit(heading)
    left = np.array([-u[1], u[0]])
    c = contacts.reset_index(drop=True)
    flags = np.zeros(len(c), bool)
    side, k, xy = c["side"].to_numpy(object), c["k"].to_numpy(), c[["x_m", "y_m"]].to_numpy(float)
    pos = {s: _leg_samples(g) for s, g in track.groupby("side")}
    for i in range(len(c)):
        same = np.flatnonzero((side == side[i]) & (k < k[i]))
        if not len(same):
            continue
        prev = same[-1]
        other = np.flatnonzero((side != side[i]) & (k > k[prev]) & (k <= k[i]))
        if not len(other):
            continue
        y_dir = left if side[i] == "R" else -left          # y′ towards the supporting leg
        if y_towards == "swing_side":
            y_dir = -y_dir
        origin = xy[prev]
        y_st = float((xy[other[-1]] - origin) @ y_dir)
        ks, leg_xy, swing = pos[side[i]]
        lo, hi = np.searchsorted(ks, int(k[prev]) + 1), np.searchsorted(ks, int(k[i]), "right")
        sw = leg_xy[lo:hi][swing[lo:hi]]
        y_sw = (sw - origin) @ y_dir if len(sw) else np.zeros(0)
        flags[i] = bool(y_st < w_c and np.any(y_sw < -w_c))    # seed001 eq. (11)
    return flags
