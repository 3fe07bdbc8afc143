"""Seeded multi-person scenes and their scans (the twin's ray caster, :mod:`gaitval.simulate.laser`).

A scene is a room (walls), furniture along its walls (tables and chairs: four thin legs
each), thin clutter (poles, stands), a sensor that stands or drives, and walkers.  Every
free choice is drawn from a named range (:data:`CHOICES`) by the scene's own seeded
generator, so a (kind, seed) pair is one scene, byte for byte.

Walkers.  A walker's body moves along a polyline at a stated speed, with stops; each leg
is a circle at shank height that alternates stance and swing (a distance-driven gait:
the feet advance only when the body does, so a standing walker's legs stand):

    u = s / S + o_f,  o_L = 0, o_R = 1/2,  φ = u − ⌊u⌋              (S: stride length)
    rel(φ) = S·β·(1/2 − φ/β)                         φ < β   (stance: the foot stays)
    rel(φ) = S·β·(−1/2 + h((φ − β)/(1 − β)))         φ ≥ β   (swing; h smoothstep)
    foot_f = path(s + rel) ± w/2 · normal                       (w: step width)

with β = 0.6 (stance share of a stride at comfortable speed; Perry & Burnfield 2010) and
the stride from the speed, S = 2·(0.35 + 0.3·v) m, within 1.0–1.6 m for 0.5–1.5 m/s
(Grieve & Gear 1966's step length–speed line, rounded).  The ground truth of a person on
a scan is the midpoint of its two legs, in the sensor frame, on every scan where ≥ 3
returns fall on its legs (the benchmark's "visible": 3 points clustered on the person).

The sensor's poses go with the scans as its odometry (``scans.meta["odometry"]``), as the
benchmark's moving robot recorded its own; the trackers read them through the
``odometry`` ego-motion role (:mod:`gaitval.crowd.bench`).
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.simulate import laser as L
from gaitval.simulate.scene import ID_CHAIR, ID_OBSTACLE, ID_POLE, ID_STICK, ID_WALL
from gaitval.types import ScanSeries

#: first object id of the people's legs (person p: legs PERSON_ID0 + 2p, + 2p + 1)
PERSON_ID0 = 100
STANCE = 0.6
DT_S = 0.1          # 10 Hz, the leg_tracker benchmark bags' rate


@dataclass(frozen=True)
class Choice:
    """A free choice of the benchmark: drawn uniformly from ``[lo, hi]`` per scene."""

    name: str
    lo: float
    hi: float
    unit: str
    source: str


def _read_choices() -> dict[str, Choice]:
    import tomllib

    with open(Path(__file__).with_name("choices.toml"), "rb") as f:
        table = tomllib.load(f)
    return {name: Choice(name, float(c["range"][0]), float(c["range"][1]), c["unit"],
                         c["source"]) for name, c in table.items()}


#: the free choices, in the order they are drawn (gaitval/crowd/choices.toml)
CHOICES = _read_choices()

#: scene kinds: sensor motion and people (docs/crowd.md)
KINDS = {
    "crossing_static": {"moving": False, "walkers": (2, 4), "meet": False, "aided": False},
    "crossing_moving": {"moving": True, "walkers": (3, 6), "meet": False, "aided": False},
    "meet_stand_turn": {"moving": False, "walkers": (2, 4), "meet": True, "aided": False},
    "crowd_moving": {"moving": True, "walkers": (6, 8), "meet": False, "aided": False},
    "assisted": {"moving": False, "walkers": (1, 2), "meet": False, "aided": True},
}
#: a development-only kind, not in the benchmark's table (:func:`draw_following`): a robot
#: following a person who stands, walks, stands and walks on, others crossing
FOLLOWING = "following"
#: development scenes (look at these) and test scenes (score only): different seeds
DEV_SEEDS = (11,)
TEST_SEEDS = (23,)


def laser_spec() -> L.LaserSpec:
    """The robot laser of leg_tracker's training bags (negative_2.bag: 768 beams of
    0.352° over 270°, 0.03-11 m), at the benchmark bags' 10 Hz, σ 10 mm."""
    inc = np.deg2rad(0.352)
    return L.LaserSpec(model="crowd laser", angle_min=-np.deg2rad(135.0), angle_increment=inc,
                       n_beams=768, scan_period_s=DT_S, range_min=0.03, range_max=11.0,
                       sigma_m=0.010, sigma_rel=0.0, dropout_prob=0.002)


@dataclass
class Walk:
    """One walker: polyline ``way`` (m, 2), body arc ``s(t)`` by breakpoints, legs."""

    way: np.ndarray
    tb: np.ndarray
    sb: np.ndarray
    stride_m: float
    width_m: float
    radius_m: float
    cane_side: int | None = None

    def _at(self, s):
        d = np.hypot(*np.diff(self.way, axis=0).T)
        cum = np.concatenate([[0.0], np.cumsum(d)])
        s = np.clip(s, 0.0, cum[-1])
        seg = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(d) - 1)
        u = self.way[seg + 1] - self.way[seg]
        u = u / np.maximum(d[seg], 1e-9)[:, None]
        p = self.way[seg] + (s - cum[seg])[:, None] * u
        return p, np.column_stack([-u[:, 1], u[:, 0]])

    def present(self, t):
        return (t >= self.tb[0]) & (t <= self.tb[-1])

    def legs(self, t):
        """(n, 2, 2) left and right leg centres in the field frame (NaN while absent)."""
        s = np.interp(t, self.tb, self.sb)
        out = np.empty((len(t), 2, 2))
        S, b = self.stride_m, STANCE
        for f, (off, side) in enumerate(((0.0, 1.0), (0.5, -1.0))):
            ph = np.mod(s / S + off, 1.0)
            x = np.clip((ph - b) / (1 - b), 0, 1)
            rel = np.where(ph < b, S * b * (0.5 - ph / b),
                           S * b * (-0.5 + x * x * (3 - 2 * x)))
            p, n = self._at(s + rel)
            out[:, f] = p + side * self.width_m / 2 * n
        out[~self.present(t)] = np.nan
        return out

    def cane(self, t, legs):
        """(n, 2) the cane's tip: beside the leg opposite its hand, 0.28 m out."""
        s = np.interp(t, self.tb, self.sb)
        _, n = self._at(s)
        side = 1.0 if self.cane_side == 0 else -1.0
        return legs[:, 1 - self.cane_side] + side * 0.28 * n


def _draw(rng, name):
    c = CHOICES[name]
    return float(rng.uniform(c.lo, c.hi))


def _stride(v):
    return 2.0 * (0.35 + 0.3 * v)


def _straight(rng, a, b, v, t0):
    """A walker from a to b at v, starting at t0."""
    d = float(np.hypot(*(b - a)))
    return Walk(np.array([a, b]), np.array([t0, t0 + d / v]), np.array([0.0, d]),
                _stride(v), _draw(rng, "step_width_m"), _draw(rng, "leg_radius_m"))


def _inside(p, room, margin=0.6):
    (x0, x1), (y0, y1) = room
    return np.array([np.clip(p[0], x0 + margin, x1 - margin),
                     np.clip(p[1], y0 + margin, y1 - margin)])


def _crossers(rng, n, T, sensor_x, room):
    out = []
    for _ in range(n):
        v = _draw(rng, "walker_speed_mps")
        tc = rng.uniform(0.15 * T, 0.8 * T)
        c = np.array([sensor_x(tc) + rng.uniform(1.5, 5.5), rng.uniform(-1.5, 1.5)])
        th = rng.choice([-1.0, 1.0]) * np.pi / 2 + rng.uniform(-0.8, 0.8)
        u = np.array([np.cos(th), np.sin(th)])
        a, b = _inside(c - 5.0 * u, room), _inside(c + 5.0 * u, room)
        t0 = tc - np.hypot(*(c - a)) / v
        out.append(_straight(rng, a, b, v, t0))
    return out


def _meeters(rng, n, T, room):
    """Pairs that walk towards each other, stand, turn (a U-turn) and walk back."""
    out = []
    for i in range(max(1, n // 2)):
        m = np.array([rng.uniform(2.0, 5.5), rng.uniform(-1.5, 1.5)])
        th = rng.uniform(0, np.pi)
        u = np.array([np.cos(th), np.sin(th)])
        stand = _draw(rng, "stand_s")
        t_meet = rng.uniform(0.25 * T, 0.5 * T)
        for sgn in (1.0, -1.0):
            v = _draw(rng, "walker_speed_mps")
            meet = m + sgn * 0.45 * u                   # 0.9 m apart when they stand
            start = _inside(m + sgn * 5.0 * u, room)
            n_ = np.array([-u[1], u[0]]) * 0.5
            way = np.array([start, meet, meet + n_, start + n_])
            d = np.hypot(*np.diff(way, axis=0).T)
            t1 = t_meet - d[0] / v
            tb = [t1, t_meet, t_meet + stand, t_meet + stand + (d[1] + d[2]) / v]
            sb = [0.0, d[0], d[0], d.sum()]
            out.append(Walk(way, np.array(tb), np.array(sb), _stride(v),
                            _draw(rng, "step_width_m"), _draw(rng, "leg_radius_m")))
    return out[:max(n, 2)]


def _aided(rng, T, room):
    """A participant with a cane and an attendant a step behind, across the view."""
    v = _draw(rng, "aided_speed_mps")
    y0 = rng.uniform(-1.0, 1.0)
    a, b = _inside(np.array([1.5, y0 - 4.0]), room), _inside(np.array([3.5, y0 + 4.0]), room)
    if rng.random() < 0.5:
        a, b = b, a
    part = _straight(rng, a, b, v, rng.uniform(0.0, 0.2 * T))
    part.cane_side = int(rng.integers(2))
    lag = _draw(rng, "attendant_lag_m")
    u = (b - a) / np.hypot(*(b - a))
    side = np.array([-u[1], u[0]]) * (0.55 if part.cane_side == 1 else -0.55)
    att = _straight(rng, a + side - lag * u, b + side - lag * u, v, part.tb[0])
    return [part, att]


def _furniture(rng, room, length):
    """Circles (x, y, r, id) of tables, chairs and poles along the walls."""
    (x0, x1), (y0, y1) = room
    circ = []
    per = length / 10.0

    def spot(lo=0.3, hi=1.3):
        side = rng.integers(2)
        y = (y0 + rng.uniform(lo, hi)) if side == 0 else (y1 - rng.uniform(lo, hi))
        return np.array([rng.uniform(x0 + 0.5, x1 - 0.5), y])

    for _ in range(rng.poisson(_draw(rng, "tables_per_10m") * per)):
        c, th = spot(0.6, 1.3), rng.uniform(0, np.pi)
        for dx, dy in ((0.6, 0.35), (0.6, -0.35), (-0.6, 0.35), (-0.6, -0.35)):
            circ.append((c[0] + dx * np.cos(th) - dy * np.sin(th),
                         c[1] + dx * np.sin(th) + dy * np.cos(th), 0.025, ID_OBSTACLE))
    for _ in range(rng.poisson(_draw(rng, "chairs_per_10m") * per)):
        c, th = spot(), rng.uniform(0, np.pi)
        for dx, dy in ((0.21, 0.21), (0.21, -0.21), (-0.21, 0.21), (-0.21, -0.21)):
            circ.append((c[0] + dx * np.cos(th) - dy * np.sin(th),
                         c[1] + dx * np.sin(th) + dy * np.cos(th), 0.012, ID_CHAIR))
    for _ in range(rng.poisson(_draw(rng, "poles_per_10m") * per)):
        c = spot(0.2, 1.6)
        circ.append((c[0], c[1], rng.uniform(0.01, 0.03), ID_POLE))
    return np.array(circ, dtype=float).reshape(-1, 4)


@dataclass
class CrowdScene:
    """A rendered scene: its scans, ground truth and what it was drawn with."""

    name: str
    kind: str
    seed: int
    scans: ScanSeries
    truth: pd.DataFrame          # k, id, x_m, y_m (sensor frame), visible scans only
    choices: dict


def make_scene(kind: str, seed: int) -> CrowdScene:
    """Draw and render one scene (module notes); deterministic in (kind, seed)."""
    walks, furn, room, pose, t, rng, choices = draw_scene(kind, seed)
    scans, truth = render(walks, furn, room, pose, t, rng)
    return CrowdScene(f"{kind}_{seed}", kind, seed, replace(scans, source=f"{kind}_{seed}"),
                      truth, choices)


def draw_scene(kind: str, seed: int):
    """A scene's parts before rendering: ``(walks, furniture circles, room, sensor poses,
    scan times, the scene's generator (next: the renderer's noise), choices)``."""
    if kind == FOLLOWING:
        return draw_following(seed)
    spec_k = KINDS[kind]
    rng = np.random.default_rng([seed, list(KINDS).index(kind)])
    T = _draw(rng, "duration_s")
    vs = _draw(rng, "sensor_speed_mps") if spec_k["moving"] else 0.0
    yaw_amp = _draw(rng, "sensor_yaw_amp_rad") if spec_k["moving"] else 0.0
    W = _draw(rng, "room_width_m")
    room = ((-1.5, 9.0 + vs * T), (-W / 2, W / 2))
    t = np.arange(0.0, T, DT_S)
    pose = np.column_stack([vs * t, np.zeros_like(t),
                            yaw_amp * np.sin(2 * np.pi * t / 8.0)])
    n = int(rng.integers(spec_k["walkers"][0], spec_k["walkers"][1] + 1))
    if spec_k["meet"]:
        walks = _meeters(rng, n, T, room)
    elif spec_k["aided"]:
        walks = _aided(rng, T, room) + _crossers(rng, n, T, lambda tc: vs * tc, room)
    else:
        walks = _crossers(rng, n, T, lambda tc: vs * tc, room)
    furn = _furniture(rng, room, 2 * (room[0][1] - room[0][0]))
    return walks, furn, room, pose, t, rng, _drawn(T, vs, yaw_amp, W, walks, furn)


def draw_following(seed: int):
    """A robot following a person (development only; the outdoor following bag's kind of
    scene, drawn, not measured on it): the person stands ``stand_s`` 1.5-2.5 m ahead of
    the sensor from the start, walks 4-8 m down the room, stands ``stand_s`` again and
    walks 4-8 m on; the robot keeps its distance, stopping when the person stops; 1-3
    walkers cross between them and the walls.  Returns :func:`draw_scene`'s tuple."""
    rng = np.random.default_rng([seed, 100])
    v = _draw(rng, "walker_speed_mps")
    gap = float(rng.uniform(1.5, 2.5))
    st1, st2 = _draw(rng, "stand_s"), _draw(rng, "stand_s")
    d1, d2 = float(rng.uniform(4.0, 8.0)), float(rng.uniform(4.0, 8.0))
    W = _draw(rng, "room_width_m")
    y0 = float(rng.uniform(-0.5, 0.5))
    T = st1 + d1 / v + st2 + d2 / v + 2.0
    tb = np.array([0.0, st1, st1 + d1 / v, st1 + d1 / v + st2, st1 + (d1 + d2) / v + st2, T])
    sb = np.array([0.0, 0.0, d1, d1, d1 + d2, d1 + d2])
    room = ((-1.5, gap + d1 + d2 + 4.0), (-W / 2, W / 2))
    target = Walk(np.array([[gap, y0], [gap + d1 + d2 + 1.0, y0]]), tb, sb, _stride(v),
                  _draw(rng, "step_width_m"), _draw(rng, "leg_radius_m"))
    t = np.arange(0.0, T, DT_S)
    yaw_amp = _draw(rng, "sensor_yaw_amp_rad")
    pose = np.column_stack([np.interp(t, tb, sb), np.full_like(t, y0),
                            yaw_amp * np.sin(2 * np.pi * t / 8.0)])
    n = int(rng.integers(1, 4))
    walks = [target] + _crossers(rng, n, T, lambda tc: float(np.interp(tc, tb, sb)), room)
    furn = _furniture(rng, room, 2 * (room[0][1] - room[0][0]))
    return walks, furn, room, pose, t, rng, _drawn(T, v, yaw_amp, W, walks, furn)


def _drawn(T, v, yaw_amp, W, walks, furn) -> dict:
    """A scene's drawn choices and counts, as its table row reports them."""
    return {"duration_s": T, "sensor_speed_mps": v, "sensor_yaw_amp_rad": yaw_amp,
            "room_width_m": W, "n_people": len(walks), "n_furniture_legs": len(furn)}


def _to_sensor(xy, pose):
    c, s = np.cos(pose[:, 2])[:, None], np.sin(pose[:, 2])[:, None]
    dx, dy = xy[..., 0] - pose[:, None, 0], xy[..., 1] - pose[:, None, 1]
    return np.stack([c * dx + s * dy, -s * dx + c * dy], axis=-1)


def render(walks, furn, room, pose, t, rng, hits=None):
    """Scans and ground truth of walkers, furniture circles and the room's walls.
    ``hits``: a dict that, when given, receives the object each beam's central sub-ray hit
    (``id``: ``PERSON_ID0 + 2p + f`` for person p's leg f, else an ``ID_*`` of
    :mod:`gaitval.simulate.scene`) and the mixed-pixel flags (``mixed``)."""
    spec = laser_spec()
    ns = len(t)
    legs = np.stack([w.legs(t) for w in walks], axis=1).reshape(ns, -1, 2)  # (ns, 2P, 2)
    canes = [w.cane(t, legs[:, 2 * i:2 * i + 2]) for i, w in enumerate(walks)
             if w.cane_side is not None]
    radii = np.repeat([w.radius_m for w in walks], 2)
    ids = PERSON_ID0 + np.arange(2 * len(walks))
    pts = [legs] + [c[:, None] for c in canes] + [np.broadcast_to(furn[None, :, :2],
                                                                 (ns, len(furn), 2))]
    xy = _to_sensor(np.concatenate(pts, axis=1), pose)
    r = np.concatenate([radii, [0.012] * len(canes), furn[:, 2]])
    oid = np.concatenate([ids, [ID_STICK] * len(canes), furn[:, 3]]).astype(np.int16)
    ell = np.concatenate([xy, np.broadcast_to(r[None, :, None], (ns, len(r), 1)),
                          np.broadcast_to(r[None, :, None], (ns, len(r), 1)),
                          np.zeros((ns, len(r), 1))], axis=2)
    (x0, x1), (y0, y1) = room
    corners = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]])
    a = _to_sensor(np.broadcast_to(corners[None, :-1], (ns, 4, 2)), pose)
    b = _to_sensor(np.broadcast_to(corners[None, 1:], (ns, 4, 2)), pose)
    seg = np.concatenate([a, b], axis=2)
    scene = L.Scene(ell, oid, seg, np.full(4, ID_WALL, dtype=np.int16))
    R, I = L.cast(scene, spec)
    m = L.measure(R, I, spec, rng)
    if hits is not None:
        hits.update(id=m["id"], mixed=m["mixed"])
    scans = ScanSeries(t=t.copy(), ranges=m["ranges"], angle_min=spec.angle_min,
                       angle_increment=spec.angle_increment, range_min=spec.range_min,
                       range_max=spec.range_max, sensor_model=spec.model,
                       mounting_height_m=0.3, meta={"odometry": pose.copy()})
    return scans, _truth(legs, xy, m, len(walks))


def _truth(legs, xy, m, n_people):
    """Per scan, each person with ≥ 3 returns on its legs (not mixed pixels): the legs'
    midpoint."""
    hit = np.where(np.isfinite(m["ranges"]) & ~m["mixed"], m["id"], -1)   # on the leg
    rows = []
    for p in range(n_people):
        on = ((hit == PERSON_ID0 + 2 * p) | (hit == PERSON_ID0 + 2 * p + 1)).sum(axis=1)
        mid = 0.5 * (xy[:, 2 * p] + xy[:, 2 * p + 1])
        for k in np.flatnonzero(on >= 3):
            rows.append((int(k), f"p{p}", float(mid[k, 0]), float(mid[k, 1])))
    return pd.DataFrame(rows, columns=["k", "id", "x_m", "y_m"]).sort_values(
        ["k", "id"], kind="stable").reset_index(drop=True)
