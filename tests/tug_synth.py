"""A small, self-contained TUG scene for the tracking tests (not the project simulator).

Two shanks (circles of diameter w_l) walk a TUG: seated at the chair, 3 m towards the
sensor, a half-circle turn around the marker, 3 m back, seated again.  Feet alternate
stance (fixed) and swing (minimum-jerk) along the path.  The sensor sits at the origin
facing +x; background: a back wall, a side wall, the chair's legs and the turn marker.
Used only by tests; the project's simulator (gaitval.simulate) is the real thing.
"""
from __future__ import annotations

import numpy as np

from gaitval.types import ScanSeries


def _path(s, x0, x_turn, r_turn):
    """Point and unit tangent at arc length s along out → semicircle → back."""
    l1 = x0 - x_turn
    lt = np.pi * r_turn
    s = np.asarray(s, dtype=float)
    p = np.zeros(s.shape + (2,))
    d = np.zeros(s.shape + (2,))
    a = s <= l1
    p[a] = np.column_stack([x0 - s[a], np.zeros(a.sum())])
    d[a] = [-1.0, 0.0]
    b = (s > l1) & (s <= l1 + lt)
    th = (s[b] - l1) / r_turn                        # turn to the left (towards +y)
    cx, cy = x_turn, r_turn
    p[b] = np.column_stack([cx - r_turn * np.sin(th), cy - r_turn * np.cos(th)])
    d[b] = np.column_stack([-np.cos(th), np.sin(th)])
    c = s > l1 + lt
    p[c] = np.column_stack([x_turn + (s[c] - l1 - lt), np.full(c.sum(), 2 * r_turn)])
    d[c] = [1.0, 0.0]
    return p, d


def _minjerk(u):
    u = np.clip(u, 0.0, 1.0)
    return u ** 3 * (10 - 15 * u + 6 * u * u)


def tug_legs(t, *, speed=1.2, turn_speed=0.6, step_time=0.5, stance_frac=0.6,
             step_width=0.18, x0=4.5, x_turn=1.5, r_turn=0.3, sit_s=1.0):
    """Left and right shank centres (n, 2) at times ``t`` (field = sensor frame).

    The body moves along the path at ``speed`` (``turn_speed`` on the half circle); the
    feet land alternately every ``step_time`` (left first) at the body's position half a
    step ahead, ± step_width/2 to the side, stay in stance for ``stance_frac`` of a stride
    and swing to the next landing on a minimum-jerk profile.
    """
    t = np.asarray(t, dtype=float)
    l1 = x0 - x_turn
    lt = np.pi * r_turn
    total = 2 * l1 + lt
    tf = np.arange(0.0, t[-1] + 10.0, 0.005)
    s = np.zeros_like(tf)
    for i in range(1, len(tf)):
        v = 0.0 if tf[i] < sit_s else (turn_speed if l1 - 0.3 < s[i - 1] < l1 + lt + 0.3
                                       else speed)
        s[i] = min(total, s[i - 1] + v * 0.005)
    t_end = tf[np.argmax(s >= total)]

    def s_at(tt):
        return np.interp(tt, tf, s)

    stride_t = 2 * step_time
    out = []
    for side, first in (("L", sit_s + step_time), ("R", sit_s + 2 * step_time)):
        land = [0.0]
        pos = [0.0]
        tl = first
        while True:
            sl = min(total, s_at(tl) + 0.5 * (s_at(tl + step_time) - s_at(tl)))
            land.append(tl)
            pos.append(sl)
            if tl > t_end:
                break
            tl += stride_t
        land, pos = np.asarray(land), np.asarray(pos)
        sigma = np.zeros_like(t)
        for n in range(1, len(land)):
            t_on = land[n]
            t_off = t_on - (1 - stance_frac) * stride_t
            u = _minjerk((t - t_off) / (t_on - t_off))
            seg = (t >= land[n - 1]) & (t < land[n] if n < len(land) - 1 else True)
            seg = (t >= (land[n - 1] if n > 1 else 0.0)) & ((t < t_on) | (n == len(land) - 1))
            sigma = np.where(seg, pos[n - 1] + u * (pos[n] - pos[n - 1]), sigma)
        sigma = np.where(t >= land[-1], pos[-1], sigma)
        p, d = _path(sigma, x0, x_turn, r_turn)
        nrm = np.column_stack([-d[:, 1], d[:, 0]])
        sgn = 1.0 if side == "L" else -1.0
        out.append(p + sgn * 0.5 * step_width * nrm)
    return out[0], out[1]


def tug_duration(speed=1.2, turn_speed=0.6, x0=4.5, x_turn=1.5, r_turn=0.3, sit_s=1.0):
    l1 = x0 - x_turn
    lt = np.pi * r_turn
    return sit_s + (2 * l1 - 0.6) / speed + (lt + 0.6) / turn_speed + 1.5


def raycast(t, centres, radius, *, angle_min=-np.deg2rad(135), inc=np.deg2rad(0.25),
            n_beams=1081, noise_m=0.01, seed=0, background=True):
    """Ranges (n, n_beams) of circles ``centres`` (list of (n, 2)) plus a static room."""
    rng = np.random.default_rng(seed)
    a = angle_min + inc * np.arange(n_beams)
    ux, uy = np.cos(a), np.sin(a)
    n = len(t)
    r = np.full((n, n_beams), np.inf)
    static = []
    if background:
        static = [((4.9, 0.15), 0.015), ((4.9, -0.3), 0.015),     # chair legs
                  ((1.5, 0.3), 0.03)]                               # turn marker (thin pole)
        # walls: x = 6 and y = -1.5 / y = 2.0
        with np.errstate(divide="ignore", invalid="ignore"):
            for dist, comp in ((6.0, ux), (-1.5, uy), (2.0, uy)):
                tt = dist / comp
                tt = np.where(tt > 0, tt, np.inf)
                r = np.minimum(r, tt[None, :])
    circles = [(np.broadcast_to(np.asarray(c, float), (n, 2)), rad) for c, rad in static]
    circles += [(np.asarray(c, float), radius) for c in centres]
    for c, rad in circles:
        proj = c[:, 0:1] * ux[None] + c[:, 1:2] * uy[None]
        perp2 = (c[:, 0:1] ** 2 + c[:, 1:2] ** 2) - proj ** 2
        disc = rad ** 2 - perp2
        with np.errstate(invalid="ignore"):
            hit = proj - np.sqrt(disc)
        hit = np.where((disc >= 0) & (hit > 0), hit, np.inf)
        r = np.minimum(r, hit)
    r = r + rng.normal(0, noise_m, r.shape)
    r[~np.isfinite(r) | (r > 30.0)] = np.nan
    return r


def tug_scans(*, leg_width=0.1, rate=40.0, seed=0, **kw):
    """(ScanSeries, truth dict side → (n, 2)) of one synthetic TUG."""
    t = np.arange(0.0, tug_duration(kw.get("speed", 1.2), kw.get("turn_speed", 0.6)),
                  1.0 / rate)
    pl, pr = tug_legs(t, **kw)
    r = raycast(t, [pl, pr], leg_width / 2, seed=seed)
    scans = ScanSeries(t=t, ranges=r, angle_min=-np.deg2rad(135),
                       angle_increment=np.deg2rad(0.25), range_min=0.1, range_max=30.0,
                       sensor_model="synthetic", mounting_height_m=0.27)
    return scans, {"L": pl, "R": pr}
