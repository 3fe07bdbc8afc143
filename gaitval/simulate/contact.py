"""Contact physics of the twin: a swinging shank goes around the standing one.

A swing of :mod:`gaitval.simulate.kinematics` moves the ankle from its toe-off point to
its heel-strike point along the straight chord.  Where that chord passes the standing
leg (a cross step, a lane change, a pivot step of a turn, a narrow step with placement
scatter) the two shanks would pass through each other.  Real legs do not: the swinging
foot's path bends around the standing leg, beside it in a narrow step, in front of or
behind it in a cross step.

Path model (:func:`swing_detours`): the swing's horizontal path is the chord plus a
sideways detour ``b · bump(τ; τc) · n`` (the whole shank, ankle and knee, moves with it):

* ``n`` is the unit normal of the chord on the side away from the standing shank at the
  moment the straight swing comes closest to it (for a cross step: in front of or behind
  the standing leg, whichever side the chord passes it on), or, when that needs a
  smaller detour (a pivot step that swings towards the standing leg), the line from the
  standing shank to the swinging one at that moment; a swing whose foot hardly travels
  (< 5 cm) always takes the latter;
* ``bump`` rises with a smoothstep from 0 at lift-off to 1 at ``τc`` and falls back to 0 at
  heel strike (zero slope at both ends: lift-off and landing are unchanged);
* ``b`` is the smallest detour (bisection) that keeps the two shank centres at least
  :data:`CONTACT_CLEARANCE_M` farther apart than one leg width at every checked height
  (:data:`CHECK_HEIGHTS_M`) through the swing — or, where the legs are closer than that
  at lift-off or at heel strike, at least as far apart as there — and ``τc`` the peak time
  (0.1–0.9) that needs the smallest ``b``.  Swings that clear the standing leg anyway
  keep ``b = 0``.

The detour is part of the swing's plan (``StepPlan.detour``), computed once from the
plan, the gait and the leg width before any frame is drawn; the kinematics read it like
any other property of the swing.  Nothing is moved after the fact.

Footholds: a foot is set down beside the other one, never on it
(:func:`separate_footholds`, applied before the detours).
"""
from __future__ import annotations

import numpy as np

#: Air between the two shanks' surfaces when one swings past the other (m): a swing passes
#: the standing leg closely but does not brush it.  An assumption (no paper measures it).
CONTACT_CLEARANCE_M = 0.01
#: Heights (m) at which the shank centres are kept apart, relative to the scan plane (the
#: walker's ``sensor_height_m``: 0.27 m UTM-30LX in TUG and MTST, 0.40 m UBG-04LX on the
#: rollator): the plane and 3 cm either side of it.
CHECK_HEIGHTS_REL_M = (-0.03, 0.0, 0.03)
CHECK_HEIGHTS_M = tuple(0.27 + d for d in CHECK_HEIGHTS_REL_M)
#: Samples per swing of the clearance search.
N_TAU = 41
#: Peak times of the detour tried (fraction of the swing).
TAU_C = np.linspace(0.10, 0.90, 17)
#: Largest detour (m) searched; a swing needing more is left at this value (and shows in
#: ``physics.csv``: the check is there to see it).
MAX_DETOUR_M = 0.40


def bump(tau: np.ndarray, tau_c: np.ndarray) -> np.ndarray:
    """0 at ``tau = 0``, 1 at ``tau_c``, 0 at ``tau = 1``; smoothstep rise and fall (C¹)."""
    tau = np.clip(np.asarray(tau, dtype=float), 0.0, 1.0)
    tau_c = np.clip(np.asarray(tau_c, dtype=float), 1e-3, 1 - 1e-3)
    up = np.clip(tau / tau_c, 0.0, 1.0)
    down = np.clip((1.0 - tau) / (1.0 - tau_c), 0.0, 1.0)
    x = np.where(tau <= tau_c, up, down)
    return x * x * (3.0 - 2.0 * x)


def _min_dist(legs, heights) -> float:
    """Closest approach of the two shank centres over the sampled times and heights."""
    a = np.stack([legs[0].point_at_height(h) for h in heights], axis=1)
    b = np.stack([legs[1].point_at_height(h) for h in heights], axis=1)
    return float(np.hypot(*(a - b).reshape(-1, 2).T).min())


def separate_footholds(plan, leg_fn, leg_width_m: float, heights=CHECK_HEIGHTS_M,
                       clearance_m: float = CONTACT_CLEARANCE_M, n_samples: int = 25):
    """The plan with every foot set down beside the other one, never on it.

    In double support the trailing shank leans forward and the leading one back, so at
    sensor height two feet placed close side by side (narrow steps, placement scatter, a
    target next to the standing foot, a short turning step) can put the shanks into each
    other although the footholds differ.  A person places the foot beside the other one:
    contact by contact, in time order, when the two shank centres come closer than one
    leg width plus :data:`CONTACT_CLEARANCE_M` (at :data:`CHECK_HEIGHTS_M`) while both feet
    stand (from the contact to the other foot's lift-off), the landing foothold moves
    sideways — across the walking direction (the two feet's mean heading), away from the
    standing foot, on the side where it already is — by the smallest amount that clears
    (bisection).  Cross steps stay cross steps; footholds that clear are not touched.
    """
    from dataclasses import replace

    target = leg_width_m + clearance_m
    xy = plan.xy.copy()
    cur = plan
    n = len(plan.t_contact)
    for i in range(2, n):
        s = int(plan.side[i])
        later = np.flatnonzero((plan.side != s) & (np.arange(n) > i))
        t_end = plan.t_off[later[0]] if len(later) else plan.t_contact[i] + 0.5
        t0 = plan.t_contact[i]
        if not (np.isfinite(t0) and np.isfinite(t_end)) or t_end <= t0:
            continue
        t = np.linspace(t0, t_end, n_samples)
        legs = [leg_fn(cur, k, t) for k in (0, 1)]
        if _min_dist(legs, heights) >= target:
            continue
        prev = np.flatnonzero((plan.side != s) & (np.arange(n) < i))
        other, h_o = xy[prev[-1]], plan.heading[prev[-1]]
        hb = float(np.angle(np.exp(1j * h_o) + np.exp(1j * plan.heading[i])))
        nb = np.array([-np.sin(hb), np.cos(hb)])
        lat = float((xy[i] - other) @ nb)
        sgn = np.sign(lat) if abs(lat) > 1e-3 else (1.0 if s == 0 else -1.0)
        base = xy[i].copy()

        def moved(d):
            x2 = xy.copy()
            x2[i] = base + d * sgn * nb
            return replace(cur, xy=x2)

        lo, hi = 0.0, MAX_DETOUR_M
        if _min_dist([leg_fn(moved(hi), k, t) for k in (0, 1)], heights) >= target:
            for _ in range(20):
                mid = 0.5 * (lo + hi)
                ok = _min_dist([leg_fn(moved(mid), k, t) for k in (0, 1)], heights) >= target
                lo, hi = (lo, mid) if ok else (mid, hi)
        xy[i] = base + hi * sgn * nb
        cur = moved(hi)
    return cur


def swing_detours(plan, leg_fn, leg_width_m: float, heights=CHECK_HEIGHTS_M,
                  clearance_m: float = CONTACT_CLEARANCE_M) -> np.ndarray:
    """Per contact ``i`` the detour of the swing that ends there: ``(n, 4)`` rows
    ``b, tau_c, n_x, n_y`` (zeros: no detour; the initial stance rows are zeros).

    ``leg_fn(plan, side, t)`` is the leg state of one side (the walker's
    :func:`~gaitval.simulate.kinematics.leg_kinematics`).  The two legs are evaluated on
    the straight swings (the plan without detours); each swing's detour is solved against
    the other leg as it is then (standing, in walking).
    """
    n = len(plan.t_contact)
    out = np.zeros((n, 4))
    target = leg_width_m + clearance_m
    idx = [i for i in range(n) if np.isfinite(plan.t_off[i]) and np.isfinite(plan.t_contact[i])
           and plan.t_contact[i] > plan.t_off[i]]
    if not idx:
        return out
    tau = np.linspace(0.0, 1.0, N_TAU)
    t_all = np.concatenate([plan.t_off[i] + tau * (plan.t_contact[i] - plan.t_off[i])
                            for i in idx])
    bare = plan if getattr(plan, "detour", None) is None else plan.without_detours()
    legs = [leg_fn(bare, s, t_all) for s in (0, 1)]
    pts = [np.stack([lg.point_at_height(h) for h in heights], axis=1) for lg in legs]  # (m, H, 2)
    for k, i in enumerate(idx):
        sl = slice(k * N_TAU, (k + 1) * N_TAU)
        s = int(plan.side[i])
        sw, st = pts[s][sl], pts[1 - s][sl]                       # (N_TAU, H, 2)
        diff = sw - st
        dist = np.hypot(diff[..., 0], diff[..., 1])
        # a swing cannot part the legs more than they are at lift-off and at heel strike
        # (those are the footholds' business: separate_footholds)
        goal = min(target, float(dist[0].min()) - 1e-4, float(dist[-1].min()) - 1e-4)
        if dist.min() >= goal:
            continue
        # chord of the foot: previous foothold of this side -> this one
        j = np.flatnonzero((plan.side == s) & (np.arange(n) < i))
        chord = plan.xy[i] - plan.xy[j[-1]] if len(j) else np.zeros(2)
        kmin = np.unravel_index(int(np.argmin(dist)), dist.shape)
        away = diff[kmin] / max(float(np.hypot(*diff[kmin])), 1e-9)
        dirs = [away]
        if np.hypot(*chord) > 0.05:
            nrm = np.array([-chord[1], chord[0]]) / np.hypot(*chord)
            dirs = [nrm if float(away @ nrm) >= 0.0 else -nrm, away]
        # every (direction, peak time) candidate at once: the smallest detour b that keeps
        # the shanks `goal` apart, by bisection on [0, MAX_DETOUR_M] (a candidate that does
        # not clear even at MAX_DETOUR_M gets MAX_DETOUR_M); elementwise the same numbers
        # as one candidate at a time
        cands = [(nrm, tc) for nrm in dirs for tc in TAU_C]
        profs = np.stack([bump(tau, tc)[:, None, None] * nrm for nrm, tc in cands])

        def clears(b):                                  # (C,) detours -> (C,) bool
            d = diff[None] + b[:, None, None, None] * profs  # (C, N_TAU, H, 2)
            return np.hypot(d[..., 0], d[..., 1]).min(axis=(1, 2)) >= goal

        lo, hi = np.zeros(len(cands)), np.full(len(cands), MAX_DETOUR_M)
        at_max = clears(hi)
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            ok = clears(mid)
            lo, hi = np.where(ok, lo, mid), np.where(ok, mid, hi)
        cand = np.where(at_max, hi, MAX_DETOUR_M)
        best = None
        for c, (nrm, tc) in enumerate(cands):           # the first of the smallest
            if best is None or cand[c] < best[0] - 1e-9:
                best = (float(cand[c]), tc, nrm)
        b, tc, nrm = best
        out[i] = (b, tc, nrm[0], nrm[1])
    return out
