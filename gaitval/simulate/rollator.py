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
from gaitval.simulate.trialsim import POLE_RADIUS_M, TrialSim, _walls, preset_number

RLT_CORNERS = {"RLT_FL": (0.30, 0.28), "RLT_FR": (0.30, -0.28),
               "RLT_RL": (-0.30, 0.28), "RLT_RR": (-0.30, -0.28)}
RLT_TOP_M = 0.85
RLT_HANDLE_M = 0.62          # pelvis → rollator centre
#: the frame's half length and half width (m): the footprint of RLT_CORNERS
RLT_HALF_L = max(abs(x) for x, _ in RLT_CORNERS.values())
RLT_HALF_W = max(abs(y) for _, y in RLT_CORNERS.values())
#: Obstacles of the obstacle scenario: (x along the walkway, side: -1 right / +1 left of
#: the path, radius), m.  Seed 002 gives the manoeuvres, not the obstacles' sizes or places.
OBSTACLES = ((2.05, -1, 0.20), (4.3, +1, 0.20))
#: The rollator's frame passes an obstacle this far from it at the closest (m; no source: a
#: hand's breadth; the preset's ``rollator.obstacle_clearance_m`` replaces it,
#: docs/robustness.md: plausible 0.05-0.30 m).  Each obstacle's lateral place is computed
#: from it along the scenario's path (:func:`obstacle_positions`), so no frame passes
#: through an obstacle.
OBSTACLE_CLEARANCE_M = 0.10
#: The room's walls stand at least this far beyond any point the rollator's frame reaches
#: on the scenario's path (m), the default room (x -2.0 to 6.5 m, y -2.2 to 3.2 m) enlarged
#: where the path needs it: a wall between the laser and the user's legs would hide them.
ROOM_MARGIN_M = 1.0


def _phase_from_plan(plan: StepPlan, labels_by_contact: np.ndarray, t_lo: float):
    """t -> phase name: the label of the next contact (phase changes at foot contacts)."""
    tc = plan.t_contact.copy()
    lab = np.asarray(labels_by_contact, dtype=object)

    def fn(t):
        i = np.searchsorted(tc, t, side="left")
        i = np.clip(i, 2, len(tc) - 1)
        return lab[i]
    return fn


#: The scenarios' path geometry (m, degrees; the preset's ``rollator.path`` replaces each
#: key; docs/simulator.md, docs/robustness.md): ``straight_m`` each straight leg of
#: scenario 1 ("a straight direction of about 3 m", seed 002 §IV), ``turn_radius_m`` the
#: pelvis's radius in its 180° turn, ``manoeuvre_radius_m`` and ``manoeuvre_deg`` the arcs
#: of scenario 2's two S-manoeuvres (no source for the last three).
PATH_DEFAULTS = {"straight_m": 3.0, "turn_radius_m": 0.6, "manoeuvre_radius_m": 1.0,
                 "manoeuvre_deg": 35.0}
#: Each key's admissible values (a preset outside them is refused, not clipped)
PATH_LIMITS = {"straight_m": (1.0, 6.0), "turn_radius_m": (0.2, 2.0),
               "manoeuvre_radius_m": (0.3, 3.0), "manoeuvre_deg": (5.0, 80.0)}
#: The obstacle scenario's straight pieces (m): before, between and after the S-manoeuvres
OBSTACLE_LINES_M = (1.0, 0.6, 1.0)


def path_geometry(cfg: dict | None) -> dict:
    """The preset's ``rollator.path`` merged over PATH_DEFAULTS, each value checked
    (ConfigError naming the key otherwise)."""
    from gaitval.errors import ConfigError

    given = (cfg or {}).get("path") or {}
    if not isinstance(given, dict) or set(given) - set(PATH_DEFAULTS):
        raise ConfigError(f"rollator.path must map some of {sorted(PATH_DEFAULTS)} to "
                          f"numbers, got {given!r}", hint="the simulation preset's "
                          "rollator section")
    return {k: float(preset_number(given.get(k, v), f"rollator.path.{k}", *PATH_LIMITS[k]))
            for k, v in PATH_DEFAULTS.items()}


def _s_starts(geo: dict) -> tuple[float, float, float]:
    """The x where each S-manoeuvre of the obstacle scenario starts, and an S's x extent."""
    a = np.deg2rad(geo["manoeuvre_deg"])
    span = 4.0 * geo["manoeuvre_radius_m"] * np.sin(a)
    first = OBSTACLE_LINES_M[0]
    return first, first + span + OBSTACLE_LINES_M[1], span


def rollator_path(scenario: str, geometry: dict | None = None) -> Path2D:
    """Scenario 1 (``straight``: a straight leg, a 180° turn, back) or 2 (``obstacle``: two
    S-manoeuvres between straight pieces) with ``geometry`` (path_geometry's keys;
    PATH_DEFAULTS when None)."""
    geo = {**PATH_DEFAULTS, **(geometry or {})}
    if scenario == "straight":
        return make_path((0.0, 0.0), 0.0, [("line", geo["straight_m"], "forward"),
                                             ("arc", geo["turn_radius_m"], np.pi, "turning"),
                                             ("line", geo["straight_m"], "return")])
    a = np.deg2rad(geo["manoeuvre_deg"])
    r = geo["manoeuvre_radius_m"]
    l0, l1, l2 = OBSTACLE_LINES_M
    return make_path((0.0, 0.0), 0.0, [("line", l0, "forward"),
                                         ("arc", r, a, "manoeuvre"), ("arc", r, -2 * a, "manoeuvre"),
                                         ("arc", r, a, "manoeuvre"), ("line", l1, "forward"),
                                         ("arc", r, -a, "manoeuvre"), ("arc", r, 2 * a, "manoeuvre"),
                                         ("arc", r, -a, "manoeuvre"), ("line", l2, "forward")])


def _frame_path(path: Path2D) -> tuple[np.ndarray, np.ndarray]:
    """The rollator frame's centre (n, 2) and heading (n,) along ``path``: RLT_HANDLE_M
    ahead of the pelvis on the path's heading (the nominal walk, without sway)."""
    xy, hd = np.asarray(path.xy, float), np.asarray(path.heading, float)
    return xy + RLT_HANDLE_M * np.column_stack([np.cos(hd), np.sin(hd)]), hd


def frame_clearance(centre: np.ndarray, heading: np.ndarray, circle) -> np.ndarray:
    """Per pose, the distance from the rollator frame's footprint (a RLT_HALF_L ×
    RLT_HALF_W rectangle about ``centre``, turned by ``heading``) to the circle
    ``(x, y, r)``; negative where they overlap."""
    ox, oy, r = circle[:3]
    dx, dy = ox - centre[:, 0], oy - centre[:, 1]
    c, s = np.cos(heading), np.sin(heading)
    lx, ly = c * dx + s * dy, -s * dx + c * dy
    qx = np.maximum(np.abs(lx) - RLT_HALF_L, 0.0)
    qy = np.maximum(np.abs(ly) - RLT_HALF_W, 0.0)
    inside = (qx == 0.0) & (qy == 0.0)
    depth = np.minimum(RLT_HALF_L - np.abs(lx), RLT_HALF_W - np.abs(ly))
    return np.where(inside, -depth, np.hypot(qx, qy)) - r


def obstacle_xs(geometry: dict | None = None) -> list[float]:
    """Each obstacle's x on the walkway: its OBSTACLES x at the default geometry; with
    other S-manoeuvres, at the same fraction of its S's x extent from the S's start."""
    geo = {**PATH_DEFAULTS, **(geometry or {})}
    *starts, span = _s_starts(geo)
    *d_starts, d_span = _s_starts(PATH_DEFAULTS)
    return [x + (s - ds) + (x - ds) / d_span * (span - d_span)
            for (x, _, _), s, ds in zip(OBSTACLES, starts, d_starts)]


def obstacle_positions(path: Path2D, clearance_m: float = OBSTACLE_CLEARANCE_M,
                       geometry: dict | None = None) -> list[tuple[float, float, float]]:
    """The obstacle scenario's obstacles ``(x, y, r)``: each at its x (obstacle_xs), on
    its side of the path, as near to it as leaves ``clearance_m`` between the rollator
    frame and the obstacle along the whole nominal path (bisection on y, 1 mm)."""
    centre, hd = _frame_path(path)
    out = []
    for (_, side, r), x in zip(OBSTACLES, obstacle_xs(geometry)):
        near = float(np.interp(x, centre[:, 0], centre[:, 1]))
        lo, hi = 0.0, 3.0           # offset from the frame's path at x, towards ``side``
        for _ in range(40):
            mid = 0.5 * (lo + hi)
            gap = frame_clearance(centre, hd, (x, near + side * mid, r)).min()
            lo, hi = (mid, hi) if gap < clearance_m else (lo, mid)
        out.append((x, round(near + side * hi, 3), r))
    return out


def room_walls(path: Path2D) -> np.ndarray:
    """The room's walls: the default room (x -2.0 to 6.5, y -2.2 to 3.2 m), each wall moved
    out to ROOM_MARGIN_M beyond the farthest reach of the rollator frame on ``path``
    (rounded up to 0.5 m)."""
    centre, _ = _frame_path(path)
    reach = np.hypot(RLT_HALF_L, RLT_HALF_W) + ROOM_MARGIN_M
    ext = lambda v: float(np.ceil(v / 0.5) * 0.5)      # noqa: E731
    x0 = min(-2.0, -ext(-(centre[:, 0].min() - reach)))
    x1 = max(6.5, ext(centre[:, 0].max() + reach))
    y0 = min(-2.2, -ext(-(centre[:, 1].min() - reach)))
    y1 = max(3.2, ext(centre[:, 1].max() + reach))
    return _walls(x0, x1, y0, y1)


def build_rollator(rng, study, subj, gp, trial, rep, scenario, cfg) -> TrialSim:
    """Rollator trial: the user walks the path, the rollator 0.62 m ahead, sensor facing back.

    The rollator frame's pose follows the user's pelvis (hands on the handles): centre
    ``pelvis + R(ψ)[0.62, 0]`` with the pelvis heading ψ smoothed over a stride.  The
    LRS sits on the rear cross-bar at ``sensor_mount`` (default x = −0.22 m, y = 0,
    yaw = π: facing the user) at 0.40 m; the two rear frame tubes (radius 0.0125 m) are
    in its 240° field of view.
    """
    geo = path_geometry(cfg)
    path = rollator_path(scenario, geo)
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
        clear = preset_number(cfg.get("obstacle_clearance_m", OBSTACLE_CLEARANCE_M),
                              "rollator.obstacle_clearance_m", 0.0, 1.0)
        obstacles = [(x, y, r, ID_OBSTACLE)
                     for x, y, r in obstacle_positions(path, float(clear), geo)]
    poles = np.array([[-1.0, -1.5], [5.5, 1.8]])
    circles = [(x, y, POLE_RADIUS_M, ID_POLE) for x, y in poles] + obstacles
    labs = plan.label
    phase = _phase_from_plan(plan, labs, 0.0)
    return TrialSim(study=study, protocol="rollator", subject=subj["subject"], trial=trial,
                    walker=walker, sensor="ubg04lx", sensor_height_m=cfg["sensor_height_m"],
                    mocap_rate_hz=cfg["mocap_rate_hz"], t_end_s=plan.t_end + 0.8,
                    circles=np.array(circles, dtype=float), walls=room_walls(path),
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
