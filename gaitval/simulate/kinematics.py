"""Gait kinematics of the simulated participants: footstep plans → shanks → leg point at sensor height.

The model is deliberately small and physical:

1. A **path** (straight lines and arcs) is walked by a sequence of **body poses**, one per
   step, spaced by the step length (shorter in turns); feet land left and right of the
   pose at half the step width, plus placement scatter (:func:`plan_steps`).
2. **Timing**: contact times advance by the step time (with subject variability);
   each foot lifts off ``(1 - stance_frac) * stride`` before its next contact, so the
   stance phase is ``stance_frac`` (≈ 0.6) of the gait cycle.
3. **Feet and shanks** (:func:`leg_kinematics`): the ankle joint centre lands just behind
   its foothold and rolls onto it over the heel, rests there in mid stance, then rolls
   forward and up over the forefoot before toe off; in swing it follows a quintic from
   the toe-off point to the next heel strike with non-zero end speeds and terminal-swing
   braking, plus a clearance arc.  The shank (ankle → knee joint centre) tilts in the
   sagittal plane of the foot along a periodic curve of the gait phase measured on real
   walks, so the shank point at sensor height is slowest early in stance and moves
   ≈ 2.5 times faster than the body at its swing peak (``gaitval.simulate.shin``).

Steps 1 and 2 (paths, footholds, timing) live in :mod:`gaitval.simulate.footsteps`, whose
public names are re-exported here; this module turns a plan into legs (step 3).

References
----------
Yorozu A, Moriguchi T, Takahashi M. Improved leg tracking considering gait phase and
spline-based interpolation during turning motion in walk tests. Sensors 2015;15:22451–22472.

Yorozu A, Nishiguchi S, Yamada M, Aoyama T, Moriguchi T, Takahashi M. Gait measurement
system for the multi-target stepping task using a laser range sensor. Sensors 2015;15:11151–11168.

Perry J, Burnfield JM. Gait Analysis: Normal and Pathological Function, 2nd ed. SLACK 2010
(shank and knee angles over the gait cycle used for the tilt curve).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from gaitval.simulate.contact import bump as detour_bump
from gaitval.simulate.footsteps import (GaitParams, Path2D, StepPlan, make_path,
                                        plan_from_footholds, plan_steps)

__all__ = ["GaitParams", "LegState", "MID_STANCE_PHASE", "Path2D", "SWING_END_ACCEL",
           "StepPlan", "TILT_REF_STEP_PER_SHANK", "TOE_OFF_PHASE", "leg_kinematics",
           "make_path", "plan_from_footholds", "plan_steps", "swing_scale"]

#: Shank tilt (knee ahead of ankle, degrees) over the gait cycle (contact at phase 0, toe off
#: at phase 0.6), measured on the real walks ``FunctionalWalk.c3d``,
#: ``PiG_Motion-FlatFoot-Full.c3d`` and ``opensim_walking2.c3d`` (10 strides; knee-ankle
#: joint-centre axis, 10 Hz low-pass; ``python -m gaitval.simulate.shin``): -12.5° (ankle
#: ahead) at contact, vertical at 11 % (seed 001 §2.5.1: "the leg is perpendicular to the
#: floor"), a steady forward roll through stance, 51° knee-ahead just after toe off, back
#: through vertical at 87 %.  Those walks have a step length of 1.6 shank lengths
#: (:data:`TILT_REF_STEP_PER_SHANK`).
_TILT_PHASE = np.array([0.00, 0.05, 0.10, 0.15, 0.25, 0.35, 0.45, 0.55, 0.65, 0.725, 0.80,
                        0.85, 0.90, 0.95, 1.00])
_TILT_DEG = np.array([-12.5, -7.1, -1.0, 3.0, 9.0, 14.8, 23.4, 38.8, 51.3, 44.1, 24.4, 6.6,
                      -9.8, -16.2, -12.5])
_TILT = CubicSpline(_TILT_PHASE, _TILT_DEG, bc_type="periodic")
TILT_REF_STEP_PER_SHANK = 1.6
TOE_OFF_PHASE = 0.60
MID_STANCE_PHASE = 0.115


#: Terminal-swing deceleration of the ankle in units of chord / swing time² (the hamstrings
#: brake the swinging leg): puts the ankle's speed peak at 60 % of swing, 1.37 × its mean,
#: as in the real walks (peak ≈ 80–85 % of the cycle, ≈ 1.35 × the mean swing speed).
SWING_END_ACCEL = -6.0


def _hermite5(tau: np.ndarray, s0, s1, a1=SWING_END_ACCEL) -> np.ndarray:
    """Quintic Hermite from 0 to 1: start slope ``s0``, end slope ``s1``, start acceleration
    0, end acceleration ``a1`` (all per unit chord and unit swing time)."""
    tau = np.clip(tau, 0.0, 1.0)
    t3, t4, t5 = tau ** 3, tau ** 4, tau ** 5
    return ((10 * t3 - 15 * t4 + 6 * t5) + s0 * (tau - 6 * t3 + 8 * t4 - 3 * t5)
            + s1 * (-4 * t3 + 7 * t4 - 3 * t5) + a1 * 0.5 * t3 * (1 - tau) ** 2)


def _minjerk(tau: np.ndarray) -> np.ndarray:
    tau = np.clip(tau, 0.0, 1.0)
    return tau ** 3 * (10 - 15 * tau + 6 * tau ** 2)


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


@dataclass
class LegState:
    """Per-frame state of one leg (arrays over the requested times).

    ``ankle``, ``knee`` (n, 3) joint centres; ``heading`` (n,) foot heading; ``stance``
    (n,) bool; ``tilt`` (n,) shank tilt (rad, knee ahead positive); ``heel_rise`` (n,)
    in [0, 1] (foot pitched heel-up: 1 at toe off, fading over early swing); ``roll_dx``
    (n,) how far the ankle is ahead of its flat-foot place over the forefoot (metres; the
    forefoot stays put on the floor while the ankle rolls over it) and ``roll_dz`` (n,)
    how far that roll lifts it.
    """

    ankle: np.ndarray
    knee: np.ndarray
    heading: np.ndarray
    stance: np.ndarray
    tilt: np.ndarray
    heel_rise: np.ndarray
    roll_dx: np.ndarray | None = None
    roll_dz: np.ndarray | None = None

    def point_at_height(self, h: float) -> np.ndarray:
        """(n, 2) horizontal position of the shank axis at height ``h`` (the "leg centre")."""
        dz = self.knee[:, 2] - self.ankle[:, 2]
        u = (h - self.ankle[:, 2]) / np.where(np.abs(dz) < 1e-6, 1e-6, dz)
        return self.ankle[:, :2] + u[:, None] * (self.knee[:, :2] - self.ankle[:, :2])


@dataclass
class _Timeline:
    """Where each requested time falls in one foot's contact / lift-off timeline.

    ``j`` last contact at or before t (0 = initial stance, ``tc = -inf``), ``jn`` the next
    one; ``off_next`` the lift-off before it (inf after the last contact); ``tau`` swing
    progress 0 → 1; ``t_c`` the last contact time (-1e9 for the initial stance),
    ``st_dur`` the stance duration and ``stance_prog`` the stance progress 0 → 1.
    """

    tc: np.ndarray
    fxy: np.ndarray
    fh: np.ndarray
    j: np.ndarray
    jn: np.ndarray
    has_next: np.ndarray
    off_next: np.ndarray
    swing: np.ndarray
    tau: np.ndarray
    t_c: np.ndarray
    st_dur: np.ndarray
    stance_prog: np.ndarray
    detour: np.ndarray | None = None


def _timeline(plan: StepPlan, side: int, t: np.ndarray) -> _Timeline:
    """Locate times ``t`` among the contacts and lift-offs of foot ``side``."""
    f = plan.foot(side)
    tc, toff, fxy, fh = f["t_contact"], f["t_off"], f["xy"], f["heading"]
    m = len(tc)
    # event timeline: contact j at tc[j] (j=0 initial, tc=-inf), lift-off j at toff[j]
    j = np.searchsorted(tc, t, side="right") - 1            # last contact <= t
    j = np.clip(j, 0, m - 1)
    jn = np.clip(j + 1, 0, m - 1)
    has_next = (j + 1) < m
    off_next = np.where(has_next, toff[jn], np.inf)
    swing = has_next & (t >= off_next)
    # swing: from foothold j to foothold j+1
    tau = np.where(swing, (t - off_next) / np.maximum(tc[jn] - off_next, 1e-6), 0.0)
    # stance progress for heel rise / phase
    t_c = np.where(np.isfinite(tc[j]), tc[j], -1e9)
    st_dur = np.where(has_next, off_next - t_c, np.inf)
    stance_prog = np.clip((t - t_c) / np.where(np.isfinite(st_dur), st_dur, 1.0), 0, 1)
    return _Timeline(tc=tc, fxy=fxy, fh=fh, j=j, jn=jn, has_next=has_next, off_next=off_next,
                     swing=swing, tau=tau, t_c=t_c, st_dur=st_dur, stance_prog=stance_prog,
                     detour=f["detour"])


def _ankle_path(tl: _Timeline, t: np.ndarray, gp: GaitParams, a_prev: np.ndarray,
                a_next: np.ndarray) -> tuple[np.ndarray, ...]:
    """Ankle joint centre (xy, z), foot heading, heel rise and forefoot roll at ``t``.

    ``a_prev``, ``a_next``: :func:`swing_scale` of the swing that ended at the last contact
    and of the next one; a shortened swing (scale < 1) scales its forefoot roll and heel
    rocker with it.  Returns ``(ax (n, 2), az, heading, heel, roll_dx, roll_dz)``; the model
    is in the notes of :func:`leg_kinematics`.
    """
    tc, fxy, fh, j, jn = tl.tc, tl.fxy, tl.fh, tl.j, tl.jn
    has_next, off_next, swing, tau = tl.has_next, tl.off_next, tl.swing, tl.tau
    t_c, st_dur = tl.t_c, tl.st_dur
    k_next, k_prev = np.minimum(a_next, 1.0), np.minimum(a_prev, 1.0)
    roll_fwd, roll_up = gp.roll_fwd_m * k_next, gp.roll_up_m * k_next
    # foot roll over the forefoot (heel off → toe off): the ankle advances roll_fwd_m·u³
    # and rises roll_up_m·u² over the last 40 % of stance (u: 0 → 1), so it leaves the
    # floor already moving forward at 3·roll_fwd_m / (0.4·stance) (real walks: ≈ 1.5 × the
    # walking speed at toe off).  Gait initiation rolls over the last 0.3 s before lift-off.
    initiating = ~np.isfinite(tc[j])
    roll_T = np.where(initiating, 0.3, 0.4 * np.where(np.isfinite(st_dur), st_dur, 1.0))
    roll_T = np.maximum(roll_T, 0.05)
    u = np.where(has_next & ~swing, np.clip(1.0 - (off_next - t) / roll_T, 0.0, 1.0), 0.0)
    heel = u ** 2
    hdg0 = fh[j]
    hdg1 = fh[jn]
    dh = (hdg1 - hdg0 + np.pi) % (2 * np.pi) - np.pi
    fwd0 = np.column_stack([np.cos(hdg0), np.sin(hdg0)])
    toe_off_xy = fxy[j] + (roll_fwd[:, None] * fwd0)       # ankle position at toe off
    # heel rocker: the heel lands with the ankle rocker_m behind its flat-foot place and
    # rolls forward over the first 25 % of stance, (1 - w)² → speed 2·rocker_m / T_load at
    # contact (real walks: the ankle still moves at ≈ 0.3–0.5 × the walking speed)
    t_load = 0.25 * np.where(np.isfinite(st_dur), st_dur, 1.0)
    w = np.where(initiating, 1.0, np.clip((t - t_c) / np.maximum(t_load, 0.02), 0.0, 1.0))
    fwd1 = np.column_stack([np.cos(hdg1), np.sin(hdg1)])
    land_xy = fxy[jn] - (gp.rocker_m * k_next)[:, None] * fwd1
    v1 = 2.0 * gp.rocker_m * k_next / np.maximum(t_load, 0.02)
    # swing: quintic from toe off (speed v0, the roll's end speed) to heel strike (speed
    # v1), terminal-swing braking SWING_END_ACCEL
    v0 = 3.0 * roll_fwd / roll_T
    chord = np.maximum(np.hypot(*(land_xy - toe_off_xy).T), 1e-3)
    t_sw = np.maximum(tc[jn] - off_next, 1e-6)
    s0 = np.clip(v0 * t_sw / chord, 0.0, 2.0)
    s1 = np.clip(v1 * t_sw / chord, 0.0, 1.0)
    g = _hermite5(tau, s0, s1)
    heading = np.where(swing, hdg0 + dh * _minjerk(tau), hdg0)
    ax = np.where(swing[:, None], toe_off_xy + (land_xy - toe_off_xy) * g[:, None],
                  fxy[j] + (roll_fwd * u ** 3 - gp.rocker_m * k_prev * (1 - w) ** 2)[:, None]
                  * fwd0)
    if tl.detour is not None and np.any(tl.detour[:, 0] != 0.0):
        # contact physics: the swing bends around the standing leg (simulate/contact.py)
        dt = tl.detour[jn]
        off = np.where(swing, dt[:, 0] * detour_bump(tau, dt[:, 1]), 0.0)
        ax = ax + off[:, None] * dt[:, 2:4]
    az = gp.ankle_height_m + roll_up * heel
    # swing height: the toe-off rise decays over the first 70 % of swing, plus a clearance
    # arc peaking early in swing (real walks: ankle highest at ≈ 15–25 % of swing)
    lift = roll_up * (1 - _smoothstep(tau / 0.7))
    bump = 0.045 * np.sin(np.pi * np.clip(tau / 0.6, 0.0, 1.0))
    az = np.where(swing, gp.ankle_height_m + lift + bump, az)
    fade = 1 - _smoothstep(tau / 0.7)
    heel = np.where(swing, fade, heel)
    roll_dx = roll_fwd * np.where(swing, fade, u ** 3)
    roll_dz = roll_up * heel
    return ax, az, heading, heel, roll_dx, roll_dz


def swing_scale(travel_m: np.ndarray, gp: GaitParams) -> np.ndarray:
    """Shank-rotation scale of a swing whose foot travels ``travel_m`` (foothold to
    foothold), relative to the walker's steady swing (``2 · step_length``).

    A swing shorter than the steady one is a geometrically scaled copy of it: the foot's
    path and the shank's rotation shrink together (factor ``r = travel / (2 L)``), so the
    knee, carried forward by the thigh through the whole swing, never moves back.  This is
    the model of gait initiation (the first step from standing travels one step length,
    not a stride: ``r ≈ 0.25``), of turning, target-adjusted and closing steps.  A longer
    swing grows the rotation sub-linearly, ``√r``, as on the real walks (1.35 × the step
    gave 1.15 × the shank range).
    """
    r = np.asarray(travel_m, dtype=float) / max(2.0 * gp.step_length_m, 1e-6)
    return np.where(r < 1.0, r, np.sqrt(r))


def _swing_amplitudes(tl: _Timeline, gp: GaitParams) -> tuple[np.ndarray, np.ndarray]:
    """Per time: the scale of the swing that ended at the last contact and of the next one.

    Before the first swing (initial stance) both are the first swing's; after the last
    contact both are the last swing's.
    """
    fxy, j, m = tl.fxy, tl.j, len(tl.fxy)
    travel = np.hypot(*np.diff(fxy, axis=0).T) if m > 1 else np.zeros(0)
    scale = swing_scale(travel, gp) if m > 1 else np.ones(1)   # scale[k]: swing k -> k+1
    a_next = np.where(tl.has_next, scale[np.clip(j, 0, len(scale) - 1)],
                      scale[np.clip(j - 1, 0, len(scale) - 1)])
    a_prev = np.where(j > 0, scale[np.clip(j - 1, 0, len(scale) - 1)], a_next)
    return a_prev, a_next


def _shank_tilt(tl: _Timeline, t: np.ndarray, gp: GaitParams,
                posture_tilt: np.ndarray | None, a_prev: np.ndarray, a_next: np.ndarray
                ) -> np.ndarray:
    """Shank tilt (rad, knee ahead positive) from the gait phase.

    The periodic tilt curve, its scaling and the standing clamps are in the notes of
    :func:`leg_kinematics`.
    """
    tc, j, has_next, off_next = tl.tc, tl.j, tl.has_next, tl.off_next
    swing, tau, t_c = tl.swing, tl.tau, tl.t_c
    # gait phase phi: stance 0..0.6, swing 0.6..1
    phi = np.where(swing, TOE_OFF_PHASE + (1 - TOE_OFF_PHASE) * tau,
                   TOE_OFF_PHASE * tl.stance_prog)
    # standing before initiation: hold mid-stance, ramp into terminal stance in 0.35 s
    pre = ~swing & ~np.isfinite(tc[j])
    ramp = _smoothstep(1 - (off_next - t) / 0.35)
    phi = np.where(pre, MID_STANCE_PHASE + (TOE_OFF_PHASE - MID_STANCE_PHASE) * ramp, phi)
    # after the last contact: go to mid-stance and stay
    post = ~has_next
    phi = np.where(post, np.minimum(MID_STANCE_PHASE,
                                    TOE_OFF_PHASE * (t - t_c) / (gp.step_time_s * 2 * gp.stance_frac)),
                   phi)
    # shank excursion grows with the step relative to the shank, sub-linearly (real walks:
    # 1.35 × the step gave 1.15 × the range, opensim_walking2 vs the two slower walks)
    amp = float(np.clip(np.sqrt(gp.step_length_m / gp.shank_length_m / TILT_REF_STEP_PER_SHANK),
                        0.5, 1.3))
    # ... and per swing with the foot's travel (swing_scale); in stance the scale passes
    # from the swing that ended at contact to the one that starts at toe off
    a = np.where(swing | pre, a_next, a_prev + (a_next - a_prev) * _smoothstep(tl.stance_prog))
    amp = amp * a
    tilt_deg = _TILT(phi) * amp
    # blend the last step's approach to standing (no tilt) so the body ends upright
    tilt = np.deg2rad(tilt_deg - np.where(post | pre, _TILT(MID_STANCE_PHASE) * amp, 0.0))
    if posture_tilt is not None:
        # the sit-to-stand lean of the shank belongs to a foot on the floor: it fades out
        # over the pre-swing ramp before the foot's first lift-off (the swing leg's shank
        # follows its swing) and applies again after the last contact (sitting down),
        # taken up over 0.25 s: a foot set down while the body already lowers (the TUG's
        # closing step) leans with it from its contact on, without a jump
        w = np.where(pre, 1.0 - ramp, np.where(post, _smoothstep((t - t_c) / 0.25), 0.0))
        tilt = tilt + w * posture_tilt
    return tilt


def leg_kinematics(plan: StepPlan, side: int, t: np.ndarray, gp: GaitParams,
                   posture_tilt: np.ndarray | None = None) -> LegState:
    """Ankle and knee joint centres of one leg at times ``t`` (vectorised over frames).

    Notes
    -----
    Stance: heel rocker ``x = x_f - rocker_m (1 - w)²`` over the first 25 % of stance
    (``w``: 0 → 1), then the ankle rests on the foothold ``x_f``; forefoot roll from 60 %
    of stance, ``x = x_f + roll_fwd_m u³``, ``z = h_a + roll_up_m u²`` (``u``: 0 → 1 at toe
    off).  Swing (``τ``: 0 → 1, chord ``c`` from the toe-off point to the landing point
    ``x_f' - rocker_m``): ``x = x0 + c·g(τ)`` with the quintic Hermite
    ``g = (10τ³ - 15τ⁴ + 6τ⁵) + s0 (τ - 6τ³ + 8τ⁴ - 3τ⁵) + s1 (-4τ³ + 7τ⁴ - 3τ⁵)
    + a1 τ³(1 - τ)²/2``, ``s0, s1`` the toe-off and heel-strike speeds times
    ``T_swing / c``, ``a1`` = :data:`SWING_END_ACCEL`; height ``h_a + roll_up_m (1 -
    smoothstep(τ/0.7)) + 0.045 sin(π min(1, τ/0.6))``.  Shank tilt ``θ(φ)`` from the
    periodic spline of the gait phase ``φ`` (0 contact, 0.6 toe off) measured on real
    walks, scaled by ``sqrt(step / shank / 1.6)``; before gait initiation and after the
    last contact the phase is clamped to mid-stance (standing), plus an optional posture
    tilt (sit-to-stand).  Constants and the real-data comparison: ``docs/simulator.md``.
    """
    tl = _timeline(plan, side, t)
    a_prev, a_next = _swing_amplitudes(tl, gp)
    ax, az, heading, heel, roll_dx, roll_dz = _ankle_path(tl, t, gp, a_prev, a_next)
    tilt = _shank_tilt(tl, t, gp, posture_tilt, a_prev, a_next)
    fwd = np.column_stack([np.cos(heading), np.sin(heading)])
    outward = (1.0 if side == 0 else -1.0) * np.column_stack([-np.sin(heading), np.cos(heading)])
    ankle = np.column_stack([ax, az])
    knee = ankle.copy()
    knee[:, :2] += gp.shank_length_m * np.sin(tilt)[:, None] * fwd
    # frontal plane: knees sit about under the hip joint centres (± knee_half_sep_m from the
    # midline) while the feet land at ± step_width/2, so each shank leans outward upward
    knee[:, :2] += max(0.0, gp.knee_half_sep_m - gp.step_width_m / 2) * outward
    knee[:, 2] += gp.shank_length_m * np.cos(tilt)
    return LegState(ankle=ankle, knee=knee, heading=heading, stance=~tl.swing, tilt=tilt,
                    heel_rise=heel, roll_dx=roll_dx, roll_dz=roll_dz)
