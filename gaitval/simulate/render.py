"""Render one simulated trial: laser log, mocap markers, truth tables, realism counts.

The sensor clock (common brief): ``t_sensor = clock_offset_s + (1 + drift_ppm·1e-6)·t_mocap``
plus timestamp jitter.  Scans are acquired every ``scan_period_s`` of the *sensor's* clock;
the log keeps every ``log_every``-th scan (MTST: Δt = 0.05 s, seed 001 §2.4).
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from gaitval.simulate import laser as L
from gaitval.simulate.markers import (BONES, JOINT_CENTRES, add_noise_and_gaps,
                                      pig_markers)
from gaitval.simulate.rollator import RLT_CORNERS, RLT_TOP_M, rollator_tubes
from gaitval.simulate.scene import ID_ATTENDANT, ID_LEFT, ID_RIGHT, ID_STICK, ID_WALL, to_sensor
from gaitval.simulate.trialsim import POLE_TOP_M, TrialSim
from gaitval.types import ScanSeries

BLOCK = 256
OCCLUDED_BELOW = 3          # fewer returning beams than this = leg occluded


def sensor_poses(sim: TrialSim, t: np.ndarray) -> np.ndarray:
    """(n, 3) sensor pose in the field at mocap times ``t``."""
    if sim.fixed_pose is not None:
        return np.tile(np.asarray(sim.fixed_pose, float), (len(t), 1))
    rp = sim.rollator(t)
    mx, my, myaw = sim.sensor_mount
    c, s = np.cos(rp[:, 2]), np.sin(rp[:, 2])
    return np.column_stack([rp[:, 0] + c * mx - s * my, rp[:, 1] + s * mx + c * my,
                            rp[:, 2] + myaw])


def _objects(sim: TrialSim, t: np.ndarray, legs) -> tuple[np.ndarray, np.ndarray]:
    """Dynamic ellipses in the field frame (n, k, 5) and their ids."""
    h = sim.sensor_height_m
    parts = [sim.walker.shank_ellipses(t, h, legs)]
    ids = [ID_LEFT, ID_RIGHT]
    if sim.attendant is not None:
        parts.append(sim.attendant.shank_ellipses(t, h))
        ids += [ID_ATTENDANT, ID_ATTENDANT]
    if sim.walker.stick_side is not None:
        st = sim.walker.stick(t, legs)
        e = np.empty((len(t), 1, 5))
        e[:, 0, 0:2] = st
        e[:, 0, 2:4] = 0.0125
        e[:, 0, 4] = 0.0
        parts.append(e)
        ids.append(ID_STICK)
    if sim.rollator is not None:
        tb = rollator_tubes(sim.rollator(t))
        e = np.empty((len(t), tb.shape[1], 5))
        e[..., 0:2] = tb[..., 0:2]
        e[..., 2] = tb[..., 2]
        e[..., 3] = tb[..., 2]
        e[..., 4] = 0.0
        parts.append(e)
        ids += [int(i) for i in tb[0, :, 3]]
        # static circles move relative to the sensor: treat them as dynamic
        if len(sim.circles):
            c = np.broadcast_to(sim.circles[None], (len(t),) + sim.circles.shape)
            e = np.empty((len(t), len(sim.circles), 5))
            e[..., 0:2] = c[..., 0:2]
            e[..., 2] = c[..., 2]
            e[..., 3] = c[..., 2]
            e[..., 4] = 0.0
            parts.append(e)
            ids += [int(i) for i in sim.circles[:, 3]]
    return np.concatenate(parts, axis=1), np.array(ids, dtype=np.int16)


def _ell_to_sensor(ell: np.ndarray, pose: np.ndarray) -> np.ndarray:
    out = ell.copy()
    out[..., 0:2] = to_sensor(ell[..., 0:2], pose)
    out[..., 4] = ell[..., 4] - pose[:, 2][:, None]
    return out


def _static_background(sim: TrialSim, spec: L.LaserSpec):
    """Ranges and ids of the fixed scene for a fixed sensor, per sub-ray."""
    pose = np.asarray(sim.fixed_pose, float)[None]
    ang = spec.sub_angles()
    R = np.full(ang.size, np.inf)
    I = np.full(ang.size, L.NO_HIT, dtype=np.int16)
    for x0, y0, x1, y1 in sim.walls:
        a = to_sensor(np.array([[x0, y0]]), pose)[0]
        b = to_sensor(np.array([[x1, y1]]), pose)[0]
        r = L.ray_segments(ang, a[0], a[1], b[0], b[1])
        I = np.where(r < R, ID_WALL, I)
        R = np.minimum(R, r)
    for cx, cy, rad, oid in sim.circles:
        c = to_sensor(np.array([[cx, cy]]), pose)[0]
        r = L.ray_ellipses(ang, c[0], c[1], rad, rad, 0.0)
        I = np.where(r < R, int(oid), I)
        R = np.minimum(R, r)
    return R, I


def scan_clock(sim: TrialSim, rng: np.random.Generator, clock: dict, spec: L.LaserSpec):
    """Scan times: (sensor timestamps as logged, true mocap times of acquisition)."""
    drift = 1 + clock["clock_drift_ppm"] * 1e-6
    off = clock["clock_offset_s"]
    # the log starts before mocap (sensor clock ≈ 0 at its first scan) and ends after it
    t_s_first = float(rng.uniform(0.0, spec.scan_period_s))
    t_s_last = off + drift * (sim.t_end_s + float(rng.uniform(0.3, 0.8)))
    ts_true = np.arange(t_s_first, t_s_last, spec.scan_period_s)
    ts_true = ts_true[::sim.log_every]
    t_mocap = (ts_true - off) / drift                       # common brief, clock model
    stamp = ts_true + clock["jitter_s"] * rng.standard_normal(ts_true.size)
    return np.round(stamp, 6), t_mocap


def render_laser(sim: TrialSim, clock: dict, rng: np.random.Generator):
    """Simulate the trial's laser log.

    Returns
    -------
    series : ScanSeries
    truth : DataFrame
        Per scan and leg: ``scan, t_s`` (sensor stamp), ``t_mocap_s``, ``side``, ``x_m,
        y_m`` (true leg centre, sensor frame), ``n_beams`` (returning beams on that leg),
        ``occluded`` (n_beams < 3), ``phase``.
    stats : dict
        Beam counts: ``n_beams_total``, ``n_returns``, ``n_mixed``, ``n_dropout``.
    poses : ndarray (n_scans, 3)
        True sensor pose in the field at each scan.
    """
    spec = L.SENSORS[sim.sensor]()
    stamp, tm = scan_clock(sim, rng, clock, spec)
    n = tm.size
    static = _static_background(sim, spec) if sim.fixed_pose is not None else None
    ranges = np.empty((n, spec.n_beams))
    rows = []
    stats = dict(n_beams_total=0, n_returns=0, n_mixed=0, n_dropout=0)
    poses = sensor_poses(sim, tm)
    for b0 in range(0, n, BLOCK):
        sl = slice(b0, min(n, b0 + BLOCK))
        t = tm[sl]
        legs = sim.walker.legs(t)
        ell, ids = _objects(sim, t, legs)
        pose = poses[sl]
        ell_s = _ell_to_sensor(ell, pose)
        if static is None:
            walls = sim.walls
            a = to_sensor(np.repeat(walls[None, :, 0:2], len(t), axis=0), pose)
            b = to_sensor(np.repeat(walls[None, :, 2:4], len(t), axis=0), pose)
            seg = np.concatenate([a, b], axis=-1)
            seg_id = np.full(len(walls), ID_WALL, dtype=np.int16)
        else:
            seg = np.empty((1, 0, 4))
            seg_id = np.empty(0, dtype=np.int16)
        scene = L.Scene(ell=ell_s, ell_id=ids, seg=seg, seg_id=seg_id)
        R, I = L.cast(scene, spec, static)
        m = L.measure(R, I, spec, rng)
        ranges[sl] = m["ranges"]
        ret = np.isfinite(m["ranges"])
        stats["n_beams_total"] += int(np.isfinite(m["true"]).sum())
        stats["n_returns"] += int(ret.sum())
        stats["n_mixed"] += int((m["mixed"] & ret).sum())
        stats["n_dropout"] += int(m["dropout"].sum())
        phase = sim.phase_fn(t) if sim.phase_fn is not None else np.full(len(t), "")
        for k, side in ((ID_LEFT, "L"), (ID_RIGHT, "R")):
            nb = ((m["id"] == k) & ret).sum(axis=1)
            rows.append(pd.DataFrame({
                "scan": np.arange(sl.start, sl.stop), "t_s": stamp[sl], "t_mocap_s": t,
                "side": side, "x_m": ell_s[:, k, 0], "y_m": ell_s[:, k, 1],
                "n_beams": nb.astype(np.int64), "occluded": nb < OCCLUDED_BELOW,
                "phase": np.asarray(phase, dtype=object)}))
    truth = pd.concat(rows, ignore_index=True).sort_values(["scan", "side"],
                                                           ignore_index=True)
    series = ScanSeries(t=stamp, ranges=ranges, angle_min=spec.angle_min,
                        angle_increment=spec.angle_increment, range_min=spec.range_min,
                        range_max=spec.range_max, sensor_model=spec.model,
                        mounting_height_m=sim.sensor_height_m)
    return series, truth, stats, poses


def mocap_frames(sim: TrialSim) -> np.ndarray:
    return np.arange(int(np.floor(sim.t_end_s * sim.mocap_rate_hz)) + 1) / sim.mocap_rate_hz


def render_mocap(sim: TrialSim, subj: dict, rng: np.random.Generator):
    """Marker trajectories (labels, xyz (n, m, 3) metres with gaps) and the leg truth.

    Returns
    -------
    labels, xyz, legs_truth (DataFrame ``t_s, side, x_m, y_m, phase``), rollator_pose
    (DataFrame ``t_s, x_m, y_m, yaw_rad`` of the sensor, or None).
    """
    t = mocap_frames(sim)
    legs = sim.walker.legs(t)
    pel, phd = sim.walker.pelvis(t)
    v = sim.variant
    mk = pig_markers(legs, pel, phd, subj, medial=v.get("medial", False),
                     bones=v.get("bones"), cluster=sim.protocol == "rollator")
    for k, (x, y) in enumerate(sim.poles, start=1):
        mk[f"POLE{k}"] = np.tile([x, y, POLE_TOP_M], (len(t), 1))
    rpose = None
    if sim.rollator is not None:
        rp = sim.rollator(t)
        c, s = np.cos(rp[:, 2]), np.sin(rp[:, 2])
        for lab, (x, y) in RLT_CORNERS.items():
            mk[lab] = np.column_stack([rp[:, 0] + c * x - s * y, rp[:, 1] + s * x + c * y,
                                       np.full(len(t), RLT_TOP_M)])
        sp = sensor_poses(sim, t)
        rpose = pd.DataFrame({"t_s": t, "x_m": sp[:, 0], "y_m": sp[:, 1],
                              "yaw_rad": np.unwrap(sp[:, 2])})
    keep = tuple(BONES + JOINT_CENTRES) + ("POLE1", "POLE2")
    mk = add_noise_and_gaps(mk, rng, rate_hz=sim.mocap_rate_hz, no_gaps=keep)
    if sim.walker.sit is not None:
        # seated, the flexed trunk and the hands hide the ASIS markers from most cameras
        seated = sim.walker.sit(t) > 0.8
        for lab in ("LASI", "RASI"):
            if rng.random() < 0.6:
                mk[lab][seated] = np.nan
    labels = sorted(mk, key=_label_order)
    xyz = np.stack([mk[lab] for lab in labels], axis=1)
    rows = []
    for k, side in enumerate("LR"):
        c = legs[k].point_at_height(sim.sensor_height_m)
        rows.append(pd.DataFrame({"t_s": t, "side": side, "x_m": c[:, 0], "y_m": c[:, 1],
                                  "phase": np.where(legs[k].stance, "stance", "swing")}))
    truth = pd.concat(rows, ignore_index=True)
    return labels, xyz, truth, rpose


_ORDER = ["ASI", "PSI", "THI", "KNE", "TIB", "ANK", "HEE", "TOE", "KNEin", "ANKin", "FEO",
          "TIO", "KJC", "AJC", "TB1", "TB2", "TB3", "TB4"]


def _label_order(lab: str):
    if lab[0] in "LR" and lab[1:] in _ORDER:
        return (0, _ORDER.index(lab[1:]), lab[0])
    return (1, 0, lab)


def gait_events(sim: TrialSim) -> pd.DataFrame:
    """True events (mocap time): foot_contact / foot_off per side, cross_step, phase boundaries."""
    p = sim.walker.plan
    rows = []
    for i in range(2, len(p.side)):
        side = "LR"[p.side[i]]
        if p.t_off[i] <= sim.t_end_s:
            rows.append((float(p.t_off[i]), "foot_off", side, "", np.nan, np.nan))
        if p.t_contact[i] <= sim.t_end_s:
            rows.append((float(p.t_contact[i]), "foot_contact", side, str(p.label[i]),
                         float(p.xy[i, 0]), float(p.xy[i, 1])))
            if p.cross[i]:
                rows.append((float(p.t_contact[i]), "cross_step", side, "", float(p.xy[i, 0]),
                             float(p.xy[i, 1])))
    if sim.protocol == "tug":
        t0, t1 = sim.variant["t_phase"]
        ta, tb = sim.variant.get("t_tug", (0.0, np.inf))
        rows += [(0.0, "phase_start", "", "seated", np.nan, np.nan)] if ta > 0 else []
        rows += [(float(ta), "phase_start", "", "forward", np.nan, np.nan),
                 (float(t0), "phase_start", "", "turning", np.nan, np.nan),
                 (float(t1), "phase_start", "", "return", np.nan, np.nan)]
        rows += [(float(tb), "phase_start", "", "seated", np.nan, np.nan)] \
            if tb <= sim.t_end_s else []
    ev = pd.DataFrame(rows, columns=["t_s", "event", "side", "label", "x_m", "y_m"])
    return ev.sort_values(["t_s", "event", "side"], ignore_index=True)


def c3d_events(ev: pd.DataFrame) -> pd.DataFrame:
    """Vicon-style EVENT rows (context Left/Right, Foot Strike / Foot Off)."""
    m = ev["event"].isin(["foot_contact", "foot_off"])
    e = ev[m]
    return pd.DataFrame({
        "context": np.where(e["side"] == "L", "Left", "Right"),
        "label": np.where(e["event"] == "foot_contact", "Foot Strike", "Foot Off"),
        "t_s": e["t_s"].to_numpy(float)})


def leg_speeds(legs_truth: pd.DataFrame) -> dict:
    """Mean horizontal speed of the leg point at sensor height in stance and in swing."""
    out = {}
    sp_all, ph_all = [], []
    for _, g in legs_truth.groupby("side", sort=True):
        t = g["t_s"].to_numpy()
        xy = g[["x_m", "y_m"]].to_numpy()
        v = np.hypot(*np.gradient(xy, t, axis=0).T)
        sp_all.append(v)
        ph_all.append(g["phase"].to_numpy())
    v = np.concatenate(sp_all)
    ph = np.concatenate(ph_all)
    moving = v > 0.02
    out["stance_speed_mps"] = float(np.mean(v[(ph == "stance")]))
    out["swing_speed_mps"] = float(np.mean(v[(ph == "swing")]))
    out["swing_peak_mps"] = float(np.percentile(v[ph == "swing"], 95)) if (ph == "swing").any() else np.nan
    out["frac_moving"] = float(moving.mean())
    return out
