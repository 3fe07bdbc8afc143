"""Footstep plans of the simulated participants: gait parameters, paths, footholds, timing.

Steps 1 and 2 of the model in :mod:`gaitval.simulate.kinematics`:

1. A **path** (straight lines and arcs, :func:`make_path`) is walked by a sequence of
   **body poses**, one per step, spaced by the step length (shorter in turns); feet land
   left and right of the pose at half the step width, plus placement scatter
   (:func:`plan_steps`).
2. **Timing**: contact times advance by the step time (with subject variability);
   each foot lifts off ``(1 - stance_frac) * stride`` before its next contact, so the
   stance phase is ``stance_frac`` (≈ 0.6) of the gait cycle
   (:func:`plan_from_footholds`).

References
----------
Yorozu A, Moriguchi T, Takahashi M. Improved leg tracking considering gait phase and
spline-based interpolation during turning motion in walk tests. Sensors 2015;15:22451–22472.

Yorozu A, Nishiguchi S, Yamada M, Aoyama T, Moriguchi T, Takahashi M. Gait measurement
system for the multi-target stepping task using a laser range sensor. Sensors 2015;15:11151–11168.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

@dataclass
class GaitParams:
    """One walker's gait (SI units).

    ``step_cv`` is the coefficient of variation of step time and length; ``place_sd_m``
    the standard deviation of foot placement around the plan (elderly > young).
    """

    step_length_m: float = 0.70
    step_width_m: float = 0.10
    step_time_s: float = 0.50
    stance_frac: float = 0.60
    step_cv: float = 0.03
    place_sd_m: float = 0.015
    shank_length_m: float = 0.42
    ankle_height_m: float = 0.08
    hip_height_m: float = 0.90
    turn_step_factor: float = 0.6       # step length in a tight turn / straight step length
    #                                     (no source; docs/simulator.md "Free choices")
    turn_time_factor: float = 1.15      # step time in a tight turn / straight step time (no
    #                                     source; the TUG uses tug.TURN_TIME_FACTOR = 1.0,
    #                                     sourced; the rollator keeps 1.15)
    knee_half_sep_m: float = 0.08       # knee joint centre from the body midline (frontal plane)
    roll_fwd_m: float = 0.14            # ankle advance over the forefoot from heel off to toe off
    roll_up_m: float = 0.09             # ankle rise from heel off to toe off
    rocker_m: float = 0.025             # ankle advance over the heel in loading response
    shank_clearance_m: float = 0.01     # air between the shanks' surfaces when one swings
    #                                     past the other (contact.CONTACT_CLEARANCE_M; no
    #                                     source; docs/simulator.md "Free choices")


def first_swing_s(gp: GaitParams, T: float) -> float:
    """Duration of the first swing of gait initiation (lift-off to the first contact).

    The leading leg's swing is a pendular motion of the leg whose duration depends little
    on the step's length: the first swing from standing lasts as long as the walker's
    steady swing, ``(1 - stance_frac) · 2 T`` (the swing phase of the cycle), while the
    foot travels only one step length (``kinematics.swing_scale``).
    """
    return (1.0 - gp.stance_frac) * 2.0 * T


@dataclass
class Path2D:
    """A densely sampled walking path: arc length ``s``, points ``xy``, heading, curvature."""

    s: np.ndarray
    xy: np.ndarray
    heading: np.ndarray
    curvature: np.ndarray
    labels: np.ndarray = field(default_factory=lambda: np.array([], dtype=object))

    @property
    def length(self) -> float:
        return float(self.s[-1])

    def at(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        x = np.interp(s, self.s, self.xy[:, 0])
        y = np.interp(s, self.s, self.xy[:, 1])
        h = np.interp(s, self.s, np.unwrap(self.heading))
        k = np.interp(s, self.s, self.curvature)
        return np.column_stack([x, y]), h, k


def make_path(start_xy, start_heading: float, segments: list[tuple], ds: float = 0.005
              ) -> Path2D:
    """Build a path from ``("line", length, label)`` and ``("arc", radius, dtheta, label)``.

    ``dtheta`` > 0 turns left (counter-clockwise).  Each sample keeps the segment label
    (e.g. ``forward``, ``turning``) so phases can be read off the path.
    """
    xy = [np.asarray(start_xy, dtype=float)]
    hd = [float(start_heading)]
    kk = [0.0]
    lab = [segments[0][-1]]
    for seg in segments:
        if seg[0] == "line":
            n = max(1, int(np.ceil(seg[1] / ds)))
            step = seg[1] / n
            for _ in range(n):
                p = xy[-1] + step * np.array([np.cos(hd[-1]), np.sin(hd[-1])])
                xy.append(p)
                hd.append(hd[-1])
                kk.append(0.0)
                lab.append(seg[-1])
        elif seg[0] == "arc":
            r, dth = float(seg[1]), float(seg[2])
            n = max(1, int(np.ceil(abs(dth) * r / ds)))
            for _ in range(n):
                h0 = hd[-1]
                h1 = h0 + dth / n
                chord = 2 * r * np.sin(abs(dth / n) / 2)
                hm = 0.5 * (h0 + h1)
                xy.append(xy[-1] + chord * np.array([np.cos(hm), np.sin(hm)]))
                hd.append(h1)
                kk.append(np.sign(dth) / r)
                lab.append(seg[-1])
        else:
            raise ValueError(f"unknown path segment {seg[0]!r}")
    xy = np.array(xy)
    s = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(xy, axis=0).T))])
    return Path2D(s=s, xy=xy, heading=np.array(hd), curvature=np.array(kk),
                  labels=np.array(lab, dtype=object))


@dataclass
class StepPlan:
    """Footholds in time order.

    Arrays of length ``n`` (one entry per foot contact, the first two are the initial
    stance of L and R at ``t_contact = -inf``-like start times): ``side`` (0 = L, 1 = R),
    ``t_contact``, ``t_off`` (lift-off time of this foot *before* this contact; NaN for
    the initial stance), ``xy`` (n, 2), ``heading`` (n,), ``label`` (path label),
    ``cross`` (True when the foot landed across the line of the other, stance foot).
    ``detour`` (n, 4), optional: per contact the sideways detour of the swing that ends
    there, ``b, tau_c, n_x, n_y`` (:mod:`gaitval.simulate.contact`; None: straight swings).
    """

    side: np.ndarray
    t_contact: np.ndarray
    t_off: np.ndarray
    xy: np.ndarray
    heading: np.ndarray
    label: np.ndarray
    cross: np.ndarray
    t_start: float
    t_end: float
    detour: np.ndarray | None = None

    def foot(self, side: int) -> dict:
        m = self.side == side
        out = {k: getattr(self, k)[m] for k in ("t_contact", "t_off", "xy", "heading",
                                                  "label", "cross")}
        out["detour"] = (np.zeros((int(m.sum()), 4)) if self.detour is None
                         else self.detour[m])
        return out

    def with_detours(self, detour: np.ndarray | None) -> "StepPlan":
        """The same plan whose swings take the detours ``detour`` (None: straight)."""
        from dataclasses import replace
        return replace(self, detour=None if detour is None else np.asarray(detour, float))

    def without_detours(self) -> "StepPlan":
        return self.with_detours(None)


@dataclass
class _Footholds:
    """Foothold lists being built by :func:`plan_steps` (one entry per contact, in order)."""

    sides: list = field(default_factory=list)
    tc: list = field(default_factory=list)
    xy: list = field(default_factory=list)
    hd: list = field(default_factory=list)
    lab: list = field(default_factory=list)
    step_times: list = field(default_factory=list)

    def add(self, side: int, t: float, xy, heading: float, label, T: float | None) -> None:
        """Append one contact; ``T`` is its step time (None for the initial stance)."""
        self.sides.append(side)
        self.tc.append(t)
        self.xy.append(xy)
        self.hd.append(heading)
        self.lab.append(label)
        if T is not None:
            self.step_times.append(T)


def _initial_stance(fh: _Footholds, path: Path2D, half_width: float) -> None:
    """Both feet beside the path start, ``half_width`` either side, contact time -inf."""
    p0, h0, _ = path.at(np.array([0.0]))
    nrm0 = np.array([-np.sin(h0[0]), np.cos(h0[0])])
    for side in (0, 1):
        sgn = 1.0 if side == 0 else -1.0
        fh.add(side, -np.inf, p0[0] + sgn * nrm0 * half_width, h0[0], path.labels[0], None)


def _walk_path(fh: _Footholds, path: Path2D, gp: GaitParams, rng: np.random.Generator,
               t0: float, first_side: int, targets: np.ndarray | None) -> tuple[float, int]:
    """Steps along the path to its end (rule in :func:`plan_steps`); returns (t, next side)."""
    s = 0.0
    t = t0
    side = first_side
    k_step = 0
    while True:
        # the curvature under the coming step sets its length and duration
        _, _, kap = path.at(s + np.linspace(0.0, gp.step_length_m, 9))
        turn = min(1.0, float(np.abs(kap).max()) * 0.35)
        L = gp.step_length_m * (1 - (1 - gp.turn_step_factor) * turn)
        L *= 1 + gp.step_cv * rng.standard_normal()
        if k_step == 0:
            L *= 0.5                                # first step starts from standing
        T = gp.step_time_s * (1 + (gp.turn_time_factor - 1) * turn)
        T *= 1 + gp.step_cv * rng.standard_normal()
        s_new = s + L
        last = s_new >= path.length - 0.5 * gp.step_length_m * 0.5
        if last:
            s_new = path.length
        p, h, _ = path.at(np.array([s_new]))
        nrm = np.array([-np.sin(h[0]), np.cos(h[0])])
        sgn = 1.0 if side == 0 else -1.0
        foot = p[0] + sgn * nrm * gp.step_width_m / 2
        if targets is not None and k_step < len(targets) and np.all(np.isfinite(targets[k_step])):
            foot = np.asarray(targets[k_step], dtype=float).copy()
        foot = foot + gp.place_sd_m * rng.standard_normal(2)
        t = t + T if k_step > 0 else t + first_swing_s(gp, T)
        fh.add(side, t, foot, h[0] + 0.03 * rng.standard_normal(),
               path.labels[int(np.searchsorted(path.s, s_new).clip(0, len(path.s) - 1))], T)
        side = 1 - side
        s = s_new
        k_step += 1
        if last:
            return t, side


def _pivot_steps(fh: _Footholds, path: Path2D, gp: GaitParams, rng: np.random.Generator,
                 t: float, side: int, end_pose: tuple, label=None,
                 end_half_width: float | None = None) -> tuple[float, int]:
    """After the path, pivot in ``n_steps`` small steps to ``end_pose`` (turn to sit, TUG);
    the steps carry ``label`` (default: the path's last label).

    The body's centre moves from between the last two footholds to ``(x, y)`` while its
    heading turns to ``heading`` in equal parts; each foot lands beside the centre on its
    own side, ``end_half_width`` from it (one turns on the spot with the feet about hip
    width apart, and they end there, as before the trial), with placement scatter.  A pivot step
    never crosses: where the scatter or the turn would set the foot down across the line
    of the standing foot (the cross-step definition of :func:`plan_from_footholds`), it is
    set down on its own side, one step width from the standing foot.  Step time: a
    turning step's (``turn_time_factor × step_time``).
    """
    ex, ey, eh, n_piv = end_pose
    hw0 = gp.step_width_m / 2
    hw1 = hw0 if end_half_width is None else float(end_half_width)
    start_c = 0.5 * (np.array(fh.xy[-1]) + np.array(fh.xy[-2]))
    h_start = fh.hd[-1]
    for j in range(1, int(n_piv) + 1):
        f = j / n_piv
        fc = min(1.0, 1.5 * f)            # the body reaches its place by 2/3 of the turn
        c = (1 - fc) * start_c + fc * np.array([ex, ey])
        h = (1 - f) * h_start + f * eh
        nrm = np.array([-np.sin(h), np.cos(h)])
        sgn = 1.0 if side == 0 else -1.0
        T = gp.step_time_s * gp.turn_time_factor * (1 + gp.step_cv * rng.standard_normal())
        t = t + T
        hw = hw1
        foot = c + sgn * nrm * hw + gp.place_sd_m * rng.standard_normal(2)
        # no crossover: lateral offset from the standing foot in the frame of the two
        # feet's mean heading (as plan_from_footholds judges a cross step)
        other, h_other = np.array(fh.xy[-1]), fh.hd[-1]
        hb = float(np.angle(np.exp(1j * h_other) + np.exp(1j * h)))
        nb = np.array([-np.sin(hb), np.cos(hb)])
        lateral = float((foot - other) @ nb) * sgn
        if lateral < gp.step_width_m:
            foot = foot + (gp.step_width_m - lateral) * sgn * nb
        fh.add(side, t, foot, h, path.labels[-1] if label is None else label, T)
        side = 1 - side
    return t, side


def plan_steps(path: Path2D, gp: GaitParams, rng: np.random.Generator, *, t0: float = 0.0,
               first_side: int = 1, end_pose: tuple | None = None,
               targets: np.ndarray | None = None, start_half_width: float | None = None,
               end_label=None, end_half_width: float | None = None) -> StepPlan:
    """Footholds and contact times along ``path``.

    Parameters
    ----------
    path : Path2D
    gp : GaitParams
    rng : Generator
    t0 : float
        Time of the first foot lift-off (gait initiation).
    first_side : int
        Foot that steps first (0 = L, 1 = R).
    end_pose : (x, y, heading, n_steps), optional
        After the path, pivot in ``n_steps`` small steps to this pose (turn to sit, TUG).
    targets : ndarray (m, 2), optional
        Foot placements to aim at instead of the nominal ones (MTST); one per step in order.
    start_half_width : float, optional
        Half distance between the feet before the first step (default: half step width;
        seated people keep their feet about hip width apart).
    end_label : str, optional
        Label of the pivot steps to ``end_pose`` and of the closing step (default: the
        path's last label), e.g. ``turn_to_sit``.
    end_half_width : float, optional
        Half distance between the feet after the closing step (default: half step width;
        the TUG sits down with the feet at hip width, as it started).

    Notes
    -----
    Step length is shortened and step time lengthened with the largest path curvature
    ``k`` under the coming step: ``L = L0 (1 - (1 - turn_step_factor) min(1, 0.35 |k|))``.  A tight turn (radius ≤ 0.35 m) uses the
    full factor.  Cross steps are not scripted: a step is flagged ``cross`` when the
    landing foot ends up on the far side of the stance foot in the stance foot's heading
    frame (the definition of seed 001 §2.5.3 applied to the truth).
    """
    fh = _Footholds()
    hw = gp.step_width_m / 2 if start_half_width is None else start_half_width
    _initial_stance(fh, path, hw)
    t, side = _walk_path(fh, path, gp, rng, t0, first_side, targets)
    if end_pose is not None:
        t, side = _pivot_steps(fh, path, gp, rng, t, side, end_pose, end_label,
                               end_half_width)
    # closing step: the trailing foot joins the other one
    h = fh.hd[-1]
    nrm = np.array([-np.sin(h), np.cos(h)])
    sgn = 1.0 if side == 0 else -1.0
    other = np.array(fh.xy[-1])
    T = gp.step_time_s * (1 + gp.step_cv * rng.standard_normal())
    t = t + T
    hw = gp.step_width_m / 2 if end_half_width is None else float(end_half_width)
    fh.add(side, t, other + (2 * sgn * nrm * hw), h, fh.lab[-1], T)

    return plan_from_footholds(np.array(fh.sides), np.array(fh.tc, dtype=float),
                               np.array(fh.xy), np.array(fh.hd),
                               np.array(fh.lab, dtype=object), np.array(fh.step_times), gp, t0)


def plan_from_footholds(sides, tc, xy, hd, lab, step_times, gp: GaitParams, t0: float
                        ) -> StepPlan:
    """Complete a foothold list (first two = initial stance) with lift-off times and cross flags.

    Lift-off of the foot landing at contact ``i``: ``t_off = t_c - (1 - stance_frac) * stride``
    with ``stride = T_i + T_{i-1}`` (two step times), so stance is ``stance_frac`` of the cycle.
    """
    t_off = np.full(len(tc), np.nan)
    st = np.concatenate([[np.nan, np.nan], np.asarray(step_times, dtype=float)])
    for i in range(2, len(tc)):
        prev_T = st[i - 1] if np.isfinite(st[i - 1]) else st[i]
        swing = (1 - gp.stance_frac) * (st[i] + prev_T)
        t_off[i] = t0 if i == 2 else max(tc[i] - swing, tc[i - 2] + 0.05)
    # cross-step truth (seed 001 §2.5.3): landing foot on the far side of the stance foot
    cross = np.zeros(len(tc), dtype=bool)
    for i in range(2, len(tc)):
        j = i - 1
        while j >= 0 and sides[j] == sides[i]:
            j -= 1
        if j < 0:
            continue
        # walking direction: bisector of the stance and the landing foot's headings
        h = float(np.angle(np.exp(1j * hd[j]) + np.exp(1j * hd[i])))
        nrm = np.array([-np.sin(h), np.cos(h)])
        lateral = float((xy[i] - xy[j]) @ nrm)      # + = left of the stance foot
        want = 1.0 if sides[i] == 0 else -1.0
        cross[i] = lateral * want < 0.0
    return StepPlan(side=sides, t_contact=tc, t_off=t_off, xy=xy, heading=hd,
                    label=lab, cross=cross, t_start=t0, t_end=float(tc[-1]))
