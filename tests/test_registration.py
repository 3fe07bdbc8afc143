"""Registration: rigid fit, calibration poles, clock synchronisation, moving sensor.

Scans here are constructed by a pure-numpy ray cast (circles for poles and legs, segments
for walls) at a known sensor pose and clock, so every expected value is known exactly.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import RegistrationError
from gaitval.groundtruth import sensor_leg_points
from gaitval.registration import (estimate_clock_offset, find_pole_candidates, fit_rigid_2d,
                                  register_poles, register_trial, registration_table)
from gaitval.registration.rigid import field_to_sensor, sensor_to_field
from gaitval.registration.trial import RECORD_FIELDS
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

# ---------------------------------------------------------------------------------------
# constructed scenes
# ---------------------------------------------------------------------------------------
ROOM = [((-3, -4), (6, -4)), ((6, -4), (6, 3)), ((6, 3), (-3, 3)), ((-3, 3), (-3, -4))]
POLES = {"POLE1": (0.3, -1.0), "POLE2": (3.1, -1.3)}
POSE = (1.4, -3.1, np.pi / 2 + 0.12)          # sensor pose in the field (x, y, yaw)
H = 0.27
LEG_R = 0.05


def raycast(angles, circles, segments):
    """Ranges (n_beams,) from the origin along ``angles`` to circles (cx, cy, r) and line
    segments ((x0, y0), (x1, y1)), all in the sensor frame; NaN = no hit."""
    u = np.stack([np.cos(angles), np.sin(angles)], -1)
    best = np.full(len(angles), np.inf)
    for cx, cy, r in circles:
        b = u[:, 0] * cx + u[:, 1] * cy
        d2 = cx * cx + cy * cy - b * b
        tt = b - np.sqrt(np.maximum(r * r - d2, 0))
        ok = (d2 < r * r) & (b > 0) & (tt > 0) & (tt < best)
        best = np.where(ok, tt, best)
    for (x0, y0), (x1, y1) in segments:
        ex, ey = x1 - x0, y1 - y0
        den = -u[:, 0] * ey + u[:, 1] * ex
        with np.errstate(all="ignore"):
            tt = (-x0 * ey + y0 * ex) / den
            s = (u[:, 0] * y0 - u[:, 1] * x0) / den
        ok = np.isfinite(tt) & (tt > 0) & (s >= 0) & (s <= 1) & (tt < best)
        best = np.where(ok, tt, best)
    best[~np.isfinite(best)] = np.nan
    return best


def legs_xy(t, v=1.0, f=0.9, y0=0.0, x0=-0.5, t_start=0.5):
    """Analytic walker along +x: each leg point advances with speed v(1 - cos(2 pi f t)),
    the right leg half a cycle later (stance ~ speed 0, swing ~ 2v).  Left leg at +y.
    Returns (n, 2, 2) field positions, legs L, R."""
    t = np.asarray(t, dtype=float)
    tt = np.clip(t - t_start, 0, None)
    w = 2 * np.pi * f
    xl = x0 + v * tt - v / w * np.sin(w * tt)
    xr = x0 + v * tt - v / w * np.sin(w * tt + np.pi) - v / w * np.sin(np.pi) * 0
    xr = xr - (-v / w * np.sin(np.pi))          # same start
    return np.stack([np.stack([xl, np.full_like(t, y0 + 0.1)], -1),
                     np.stack([xr, np.full_like(t, y0 - 0.1)], -1)], axis=1)


def synthetic_mocap(rate=200.0, duration=4.0, poles=POLES, extra=None, rot=0.0):
    """MocapTrial with PiG bone outputs (vertical shanks), ASIS and pole markers."""
    t = np.arange(int(duration * rate)) / rate
    L = legs_xy(t)
    c, s = np.cos(rot), np.sin(rot)
    Rm = np.array([[c, -s], [s, c]])
    L = L @ Rm.T
    labels, cols = [], []

    def add(lb, xy, z):
        labels.append(lb)
        cols.append(np.column_stack([xy, np.full(len(t), z)]))

    for j, S in enumerate("LR"):
        add(S + "FEO", L[:, j], 0.50)
        add(S + "TIO", L[:, j], 0.08)
    add("LASI", L.mean(axis=1) + np.array([0, 0.12]) @ Rm.T, 0.9)
    add("RASI", L.mean(axis=1) + np.array([0, -0.12]) @ Rm.T, 0.9)
    for lb, p in (poles or {}).items():
        add(lb, np.tile(p, (len(t), 1)), 1.2)
    for lb, arr in (extra or {}).items():
        labels.append(lb)
        cols.append(arr)
    return MocapTrial("synthetic.c3d", rate, 1, labels, np.stack(cols, axis=1))


def synthetic_scans(pose=POSE, offset=2.345, drift_ppm=0.0, rate=40.0, duration=4.0,
                    poles=POLES, blocker=None, seed=0, noise=0.001, clutter=True):
    """LRS scans of the synthetic walker: UTM-30LX geometry, mm quantisation."""
    rng = np.random.default_rng(seed)
    n = int(duration * rate)
    t_m = np.arange(n) / rate + 0.01
    t_s = offset + (1 + drift_ppm * 1e-6) * t_m
    ang = np.deg2rad(-135) + np.deg2rad(0.25) * np.arange(1081)
    walls = [tuple(tuple(field_to_sensor(np.array(p), *pose)) for p in seg) for seg in ROOM]
    pole_s = [tuple(field_to_sensor(np.array(p), *pose)) for p in poles.values()]
    chair = [(-1.8, 1.5), (-1.4, 1.5), (-1.8, 1.9), (-1.4, 1.9)] if clutter else []
    chair_s = [tuple(field_to_sensor(np.array(p), *pose)) for p in chair]
    L = legs_xy(t_m)
    R = np.empty((n, 1081))
    for k in range(n):
        circ = [(x, y, 0.025) for x, y in pole_s] + [(x, y, 0.012) for x, y in chair_s]
        for j in range(2):
            x, y = field_to_sensor(L[k, j], *pose)
            circ.append((x, y, LEG_R))
        if blocker is not None and blocker(k, n):
            bx, by = field_to_sensor(np.array(blocker.where), *pose)
            circ.append((bx, by, 0.12))
        r = raycast(ang, circ, walls)
        R[k] = np.round((r + rng.normal(0, noise, r.shape)) * 1000) / 1000
    return ScanSeries(t=t_s, ranges=R, angle_min=float(ang[0]),
                      angle_increment=float(ang[1] - ang[0]), range_min=0.1,
                      range_max=30.0, sensor_model="constructed", mounting_height_m=H,
                      source="synthetic.scan.parquet")


TRIAL = {"trial": "T01", "protocol": "tug", "sensor_height_m": H, "clock_offset_s": ""}
SUBJECT = {"subject": "S01", "leg_width_m": 2 * LEG_R}


def register(mocap, sensor, trial, subject, cfg):
    """The pipeline's order: the leg points once, then the registration with them."""
    legs = sensor_leg_points(mocap, sensor, trial, subject, cfg)
    return register_trial(mocap, sensor, trial, subject, cfg, legs=legs)


@pytest.fixture(scope="module")
def scene():
    return synthetic_mocap(), synthetic_scans()


# ---------------------------------------------------------------------------------------
# rigid fit
# ---------------------------------------------------------------------------------------
def test_fit_rigid_2d_hand_case():
    # a quarter turn and a shift: (1,0)->(2,4), (0,1)->(1,3), (0,0)->(2,3)
    src = np.array([[1.0, 0.0], [0.0, 1.0], [0.0, 0.0]])
    dst = np.array([[2.0, 4.0], [1.0, 3.0], [2.0, 3.0]])
    x, y, yaw, res = fit_rigid_2d(src, dst)
    assert (x, y) == pytest.approx((2.0, 3.0), abs=1e-12)
    assert yaw == pytest.approx(np.pi / 2, abs=1e-12)
    assert res.max() < 1e-12


def test_sensor_field_round_trip():
    p = np.array([[0.3, -1.2], [4.0, 2.0]])
    q = sensor_to_field(p, *POSE)
    assert field_to_sensor(q, *POSE) == pytest.approx(p, abs=1e-12)
    # the beam-0 axis points along yaw
    d = sensor_to_field(np.array([1.0, 0.0]), *POSE) - np.array(POSE[:2])
    assert np.arctan2(d[1], d[0]) == pytest.approx(POSE[2])


# ---------------------------------------------------------------------------------------
# poles
# ---------------------------------------------------------------------------------------
def test_pole_candidates_include_both_poles(scene):
    _, scans = scene
    cand = find_pole_candidates(scans)
    for p in POLES.values():
        ps = field_to_sensor(np.array(p), *POSE)
        d = np.hypot(cand["xs_m"] - ps[0], cand["ys_m"] - ps[1])
        assert d.min() < 0.003   # centre within 3 mm (range noise 1 mm, quantisation 1 mm)


def test_pose_recovered_from_two_poles(scene):
    mocap, scans = scene
    fit = register_poles(scans, mocap, leg_xy_field=legs_xy(np.linspace(0, 4, 200)).reshape(-1, 2))
    assert np.hypot(fit.x_m - POSE[0], fit.y_m - POSE[1]) < 0.005
    assert abs(np.rad2deg(fit.yaw_rad - POSE[2])) < 0.2
    assert fit.worst_residual_m < 0.005
    # the 180-degree alternative was considered and lost on motion evidence
    assert len(fit.motion_score) == 2 and max(fit.motion_score.values()) > 0.5


class _Blocker:
    """A person (0.24 m wide) standing in front of POLE1 for the first 40 % of the scans."""
    where = (0.3 + 0.0, -1.0 - 0.6)

    def __call__(self, k, n):
        return k < 0.4 * n


def test_pole_hidden_for_part_of_window_still_robust():
    mocap = synthetic_mocap()
    blk = _Blocker()
    # put the blocker on the line of sight sensor -> POLE1
    p1, s = np.array(POLES["POLE1"]), np.array(POSE[:2])
    blk.where = tuple(s + 0.6 * (p1 - s))
    scans = synthetic_scans(blocker=blk)
    # POLE1 really is hidden in those scans
    ps = field_to_sensor(p1, *POSE)
    beam = int(round((np.arctan2(ps[1], ps[0]) - scans.angle_min) / scans.angle_increment))
    assert np.nanmax(scans.ranges[:10, beam]) < np.hypot(*ps) - 0.5
    fit = register_poles(scans, mocap, leg_xy_field=legs_xy(np.linspace(0, 4, 200)).reshape(-1, 2))
    assert np.hypot(fit.x_m - POSE[0], fit.y_m - POSE[1]) < 0.005
    assert abs(np.rad2deg(fit.yaw_rad - POSE[2])) < 0.2


def test_only_one_visible_pole_is_an_error():
    mocap = synthetic_mocap()
    scans = synthetic_scans(poles={"POLE1": POLES["POLE1"]}, clutter=False)
    with pytest.raises(RegistrationError, match="pole") as ei:
        register_poles(scans, mocap, trial="T01")
    assert "T01" in str(ei.value)


def test_c3d_without_pole_markers_is_an_error(scene):
    _, scans = scene
    mocap = synthetic_mocap(poles={})
    with pytest.raises(RegistrationError, match="POLE1, POLE2") as ei:
        register(mocap, scans, TRIAL, SUBJECT, {})
    assert "T01" in str(ei.value) and "synthetic" in str(ei.value)


def test_implausible_residual_is_refused(scene):
    _, scans = scene
    moved = dict(POLES, POLE2=(POLES["POLE2"][0] + 0.06, POLES["POLE2"][1]))
    mocap = synthetic_mocap(poles=moved)
    with pytest.raises(RegistrationError, match="residual"):
        register_poles(scans, mocap, leg_xy_field=legs_xy(np.linspace(0, 4, 200)).reshape(-1, 2))


def test_two_pole_ambiguity_without_motion():
    """A static scene cannot tell the pose from its 180-degree turn: clear error by default,
    and the documented bearing rule when configured."""
    poles = {"POLE1": POLES["POLE2"], "POLE2": POLES["POLE1"]}
    mocap = synthetic_mocap(poles=poles)
    scans = synthetic_scans(clutter=False, poles=poles)
    with pytest.raises(RegistrationError, match="180"):
        register_poles(scans, mocap, leg_xy_field=None)
    # bearing rule: POLE1 must be at the smaller beam angle
    p1 = field_to_sensor(np.array(poles["POLE1"]), *POSE)
    p2 = field_to_sensor(np.array(poles["POLE2"]), *POSE)
    assert np.arctan2(p1[1], p1[0]) < np.arctan2(p2[1], p2[0])
    fit = register_poles(scans, mocap, {"pole_ambiguity": "bearing"})
    assert np.hypot(fit.x_m - POSE[0], fit.y_m - POSE[1]) < 0.005


def test_three_poles_distance_pattern():
    poles = dict(POLES, POLE3=(1.2, -0.6))
    mocap = synthetic_mocap(poles=poles)
    scans = synthetic_scans(poles=poles)
    fit = register_poles(scans, mocap)
    assert np.hypot(fit.x_m - POSE[0], fit.y_m - POSE[1]) < 0.005
    assert set(fit.residual_m) == {"POLE1", "POLE2", "POLE3"}


# ---------------------------------------------------------------------------------------
# clock
# ---------------------------------------------------------------------------------------
def _smooth_signal(t, seed=3):
    rng = np.random.default_rng(seed)
    f = rng.uniform(0.2, 3.0, 12)
    ph = rng.uniform(0, 2 * np.pi, 12)
    return np.sum(np.sin(2 * np.pi * f[None] * t[:, None] + ph[None]), axis=1)


def test_generic_offset_recovered_subsample():
    # a at 200 Hz on the mocap clock; b at 50 Hz on a clock reading t_b = t_a + 1.2345
    t_a = np.arange(0, 30, 1 / 200)
    t_b = 1.2345 + np.arange(0.013, 29, 1 / 50)
    sig_a = _smooth_signal(t_a)
    sig_b = _smooth_signal(t_b - 1.2345)
    tau, peak = estimate_clock_offset(t_a, sig_a, t_b, sig_b, max_lag_s=3.0)
    assert tau == pytest.approx(1.2345, abs=0.5e-3)   # well below one 5 ms sample
    assert peak > 0.99


def test_generic_offset_unix_stamps_and_noise():
    t_a = np.arange(0, 20, 1 / 100)
    off = 1.7e9 + 0.0371
    t_b = off + np.arange(0, 20, 1 / 40)
    rng = np.random.default_rng(1)
    sig_b = _smooth_signal(t_b - off) + rng.normal(0, 0.5, len(t_b))
    tau, peak = estimate_clock_offset(t_a, _smooth_signal(t_a), t_b, sig_b, max_lag_s=2.0)
    assert tau - 1.7e9 == pytest.approx(0.0371, abs=2e-3)
    assert 0.5 < peak < 1.0


def test_clock_offset_recovered_from_scans(scene):
    mocap, scans = scene
    rec = register(mocap, scans, TRIAL, SUBJECT, {})
    assert rec.clock_offset_s == pytest.approx(2.345, abs=0.5 / 40)  # half a scan period
    assert abs(rec.clock_offset_s - 2.345) < 0.003
    assert rec.sync_peak > 0.5
    assert rec.clock_drift_ppm == 0.0
    assert rec.joint_centre_source == "pig_bone_outputs"
    assert rec.gt_frames_excluded == 0
    assert np.hypot(rec.x_m - POSE[0], rec.y_m - POSE[1]) < 0.005


def test_lrs_registration_needs_the_leg_points(scene):
    """Registration does not compute leg points (that would import the ground truth): an LRS
    trial without them is a programming error that says what to pass."""
    mocap, scans = scene
    with pytest.raises(TypeError, match="sensor_leg_points"):
        register_trial(mocap, scans, TRIAL, SUBJECT, {})


def test_manual_offset_overrides(scene):
    mocap, scans = scene
    rec = register(mocap, scans, dict(TRIAL, clock_offset_s="2.5"), SUBJECT, {})
    assert rec.clock_offset_s == 2.5 and np.isnan(rec.sync_peak)


def test_narrow_lag_search_equals_the_wide_one():
    """A search of +-0.2 s around a known centre correlates only the band of the long
    signal that can meet the short one (the drift windows'); its offset and peak equal
    those of a search over every lag that finds the same peak."""
    t_a = np.arange(0, 120, 1 / 100)
    t_b = 0.4321 + np.arange(50, 58, 1 / 40)             # 8 s in the middle of 120 s
    sig_a, sig_b = _smooth_signal(t_a), _smooth_signal(t_b - 0.4321)
    wide = estimate_clock_offset(t_a, sig_a, t_b, sig_b, max_lag_s=60.0, centre_s=0.4)
    narrow = estimate_clock_offset(t_a, sig_a, t_b, sig_b, max_lag_s=0.2, centre_s=0.4)
    assert wide[0] == pytest.approx(0.4321, abs=1e-3)
    assert narrow[0] == pytest.approx(wide[0], abs=1e-12)
    assert narrow[1] == pytest.approx(wide[1], abs=1e-12)


def test_drift_estimated_on_long_signals():
    t_a = np.arange(0, 240, 1 / 100)
    off, ppm = 0.8, 300.0
    t_b_true = np.arange(0, 239, 1 / 50)               # mocap times of the samples
    t_b = off + (1 + ppm * 1e-6) * t_b_true
    from gaitval.registration.clock import estimate_clock
    ce = estimate_clock(t_a, _smooth_signal(t_a)[:, None], t_b, _smooth_signal(t_b_true)[:, None],
                        {"drift_min_duration_s": 60, "sync_windows": 4})
    assert ce.clock_drift_ppm == pytest.approx(ppm, abs=20)
    assert ce.clock_offset_s == pytest.approx(off, abs=2e-3)


def test_registration_table_columns(scene):
    mocap, scans = scene
    rec = register(mocap, scans, dict(TRIAL, clock_offset_s=2.345), SUBJECT, {})
    df = registration_table([rec])
    assert tuple(df.columns) == RECORD_FIELDS
    assert df.loc[0, "trial"] == "T01"


# ---------------------------------------------------------------------------------------
# moving sensor (rollator)
# ---------------------------------------------------------------------------------------
MOUNT = {"x_m": -0.35, "y_m": 0.02, "yaw_rad": np.pi + 0.03}   # at the rear, facing the user


def rollator_markers(t):
    """Rollator 0.7 m ahead of the walker's mean leg position, weaving slightly."""
    L = legs_xy(t).mean(axis=1)
    yaw = 0.15 * np.sin(2 * np.pi * 0.3 * t)
    cen = L + np.column_stack([0.7 * np.cos(yaw), 0.7 * np.sin(yaw)])
    pts = {}
    for lb, (fx, fy) in {"RLT_FL": (0.3, 0.28), "RLT_FR": (0.3, -0.28),
                         "RLT_RL": (-0.3, 0.28), "RLT_RR": (-0.3, -0.28)}.items():
        x = cen[:, 0] + np.cos(yaw) * fx - np.sin(yaw) * fy
        y = cen[:, 1] + np.sin(yaw) * fx + np.cos(yaw) * fy
        pts[lb] = np.column_stack([x, y, np.full(len(t), 0.9)])
    return cen, yaw, pts


def test_rollator_pose_and_clock():
    from gaitval.registration.moving import rollator_pose, sensor_pose_from_rollator
    rate = 100.0
    t = np.arange(int(4 * rate)) / rate
    cen, yaw, pts = rollator_markers(t)
    mocap = synthetic_mocap(rate=rate, poles={}, extra=pts)
    rp = rollator_pose(mocap)
    assert rp[:, :2] == pytest.approx(cen, abs=1e-9)
    assert rp[:, 2] == pytest.approx(yaw, abs=1e-9)
    sp = sensor_pose_from_rollator(rp, MOUNT)
    # the mount point expressed back in the rollator frame is the mount
    back = field_to_sensor(sp[:, :2], rp[:, 0], rp[:, 1], rp[:, 2])
    assert back == pytest.approx(np.tile([MOUNT["x_m"], MOUNT["y_m"]], (len(t), 1)), abs=1e-9)

    # scans from the moving sensor: only the legs (UBG-04LX-like, 240 deg)
    srate, off = 1 / 0.028, -0.75
    ts_m = np.arange(0.02, 3.9, 1 / srate)
    cen_s, yaw_s, _ = rollator_markers(ts_m)
    rp_s = np.column_stack([cen_s, yaw_s])
    sp_s = sensor_pose_from_rollator(rp_s, MOUNT)
    ang = np.deg2rad(-120) + np.deg2rad(0.352) * np.arange(682)
    L = legs_xy(ts_m)
    R = np.array([raycast(ang, [(*field_to_sensor(L[k, j], *sp_s[k]), LEG_R) for j in range(2)],
                          []) for k in range(len(ts_m))])
    scans = ScanSeries(t=off + ts_m, ranges=np.round(R * 1000) / 1000, angle_min=float(ang[0]),
                       angle_increment=float(ang[1] - ang[0]), range_min=0.02, range_max=5.6,
                       mounting_height_m=0.40, source="rollator.scan.parquet")
    trial = {"trial": "R01", "protocol": "rollator", "sensor_height_m": 0.40}
    rec = register(mocap, scans, trial, SUBJECT, {"rollator": {"sensor_mount": MOUNT}})
    assert abs(rec.clock_offset_s - off) < 0.5 * 0.028
    assert np.isnan(rec.x_m) and np.isnan(rec.pole_residual_m)

    from gaitval.groundtruth import ground_truth
    gt = ground_truth(mocap, scans, rec, trial, SUBJECT, {"rollator": {"sensor_mount": MOUNT}})
    v = gt[gt.valid]
    truth = np.concatenate([field_to_sensor(L[v.scan[v.side == s].to_numpy(), j],
                                            *sp_s[v.scan[v.side == s].to_numpy()].T)
                            for j, s in enumerate("LR")])
    got = np.concatenate([v[v.side == s][["xs_m", "ys_m"]].to_numpy() for s in "LR"])
    # leg points in the laser frame within 2 mm (clock error x leg speed)
    assert np.abs(got - truth).max() < 0.004
    assert np.median(np.abs(got - truth)) < 0.001


# ---------------------------------------------------------------------------------------
# ultrasonic
# ---------------------------------------------------------------------------------------
def test_ultrasonic_anchor_frame_and_clock():
    from gaitval.registration.trial import anchor_distances
    rate = 200.0
    t = np.arange(0, 20, 1 / rate)
    anchors_us = np.array([[0, 0, 0], [0.324, 0, 0], [0.324, 0.230, 0], [0, 0.230, 0]])  # seed 003 §4.1
    yaw, tr = 0.3, np.array([1.0, -0.5, 0.05])
    Rz = np.array([[np.cos(yaw), -np.sin(yaw), 0], [np.sin(yaw), np.cos(yaw), 0], [0, 0, 1]])
    anc_f = anchors_us @ Rz.T + tr
    tx = np.column_stack([1.3 + 0.25 * np.sin(2 * np.pi * 0.9 * t), 0.3 + 0.02 * np.sin(2 * np.pi * 1.8 * t),
                          0.45 + 0.06 * np.clip(np.sin(2 * np.pi * 0.9 * t + 1), 0, None)])
    extra = {"TX": tx, **{f"ANC{k + 1}": np.tile(anc_f[k], (len(t), 1)) for k in range(4)}}
    mocap = synthetic_mocap(rate=rate, duration=20, poles={}, extra=extra)
    off = 0.4321
    tu_m = np.arange(0.05, 19.5, 1 / 50)
    tx_u = np.column_stack([np.interp(tu_m, t, tx[:, j]) for j in range(3)])
    dist = np.linalg.norm(tx_u[:, None] - anc_f[None], axis=2)
    temp = np.full(len(tu_m), 22.0)
    c = 331.5 + 0.6 * 22.0          # seed 003 eq. (2), what the pipeline converts with
    log = UltrasonicLog(t=off + tu_m, temperature_c=temp, tof_s=dist / c,
                        anchors=pd.DataFrame({"anchor": ["R1", "R2", "R3", "R4"],
                                              "x_m": anchors_us[:, 0], "y_m": anchors_us[:, 1],
                                              "z_m": anchors_us[:, 2]}), source="t.us.parquet")
    assert anchor_distances(log) == pytest.approx(dist, abs=1e-12)
    trial = {"trial": "U01", "protocol": "treadmill"}
    from gaitval.groundtruth import sensor_leg_points
    rec = register_trial(mocap, log, trial, None, {},
                         legs=sensor_leg_points(mocap, log, trial, None, {}))
    assert rec.yaw_rad == pytest.approx(yaw, abs=1e-6)
    assert (rec.x_m, rec.y_m) == pytest.approx((1.0, -0.5), abs=1e-6)
    assert abs(rec.clock_offset_s - off) < 0.5 / 50
    assert abs(rec.clock_offset_s - off) < 0.002
    assert rec.joint_centre_source == "tx_marker"
    from gaitval.groundtruth import ground_truth
    gt = ground_truth(mocap, log, rec, trial, None, {})
    v = gt[gt.valid]
    # TX in the ultrasonic frame equals the (filtered) truth; the 10 Hz low-pass barely
    # touches a 0.9 Hz motion
    tx_true_us = (tx_u - tr) @ Rz
    err = np.abs(v[["xs_m", "ys_m", "zs_m"]].to_numpy() - tx_true_us[v["sample"].to_numpy()])
    assert np.median(err) < 0.002


# ---------------------------------------------------------------------------------------
# acceptance on the tiny simulated study (truth/ is read here, in tests only)
# ---------------------------------------------------------------------------------------
def _read_us_log(path):
    """Independent route to an ultrasonic log (pyarrow directly, not gaitval.io)."""
    import json

    import pyarrow.parquet as pq
    tab = pq.read_table(path)
    meta = json.loads(tab.schema.metadata[b"gaitval:ultrasonic"])
    anchors = pd.DataFrame(meta["anchors"])
    df = tab.to_pandas()
    tof = np.column_stack([df[f"tof_{a}_s"].to_numpy(dtype=float, copy=True)
                           for a in anchors["anchor"]])
    tof[~(tof > 0)] = np.nan
    return UltrasonicLog(t=df["t_s"].to_numpy(dtype=float, copy=True),
                         temperature_c=df["temperature_c"].to_numpy(dtype=float, copy=True),
                         anchors=anchors, tof_s=tof, source=str(path))


@pytest.fixture(scope="module")
def tiny(tiny_simulated):
    import yaml
    out = tiny_simulated                      # generate_study(out, "tiny"), read only
    trials = pd.read_csv(out / "trials.csv", dtype=str, keep_default_na=False)
    subjects = pd.read_csv(out / "subjects.csv", dtype=str, keep_default_na=False)
    cfg = yaml.safe_load((out / "study.yaml").read_text()) if (out / "study.yaml").exists() else {}
    return out, trials, subjects.set_index("subject"), cfg


def _pole_visible(scans, pole_s):
    """Truth-side check: does any scan return within 5 cm of the pole's front?"""
    b = int(round((np.arctan2(pole_s[1], pole_s[0]) - scans.angle_min) / scans.angle_increment))
    r = scans.ranges[:, max(b - 1, 0):b + 2]
    with np.errstate(invalid="ignore"):
        return bool(np.any(np.abs(r - (np.hypot(*pole_s) - 0.025)) < 0.05))


@pytest.mark.slow
def test_tiny_study_lrs_acceptance(tiny):
    from gaitval.groundtruth import ground_truth, leg_points
    from gaitval.io.c3d import read_c3d
    from gaitval.io.scanlog import read_scanlog
    from gaitval.registration.poles import mocap_pole_positions
    from gaitval.registration.rigid import wrap_angle

    out, trials, subjects, cfg = tiny
    truth = pd.read_csv(out / "truth" / "sensor_pose.csv").set_index("trial")
    n_checked = 0
    for tr in trials[trials.sensor_kind == "lrs"].to_dict("records"):
        mocap = read_c3d(out / tr["mocap_file"])
        scans = read_scanlog(out / tr["sensor_file"])
        sub = subjects.loc[tr["subject"]].to_dict()
        T = truth.loc[tr["trial"]]
        period = float(np.median(np.diff(scans.t)))
        if tr["protocol"] != "rollator":
            poles = mocap_pole_positions(mocap)[["x_m", "y_m"]].to_numpy()
            vis = [_pole_visible(scans, field_to_sensor(p, T.x_m, T.y_m, T.yaw_rad)) for p in poles]
            if not all(vis):
                # a pole the sensor never sees: the documented behaviour is a clear error
                with pytest.raises(RegistrationError, match="pole") as ei:
                    register(mocap, scans, tr, sub, cfg)
                assert tr["trial"] in str(ei.value)
                continue
        rec = register(mocap, scans, tr, sub, cfg)
        n_checked += 1
        if tr["protocol"] != "rollator":
            assert np.hypot(rec.x_m - T.x_m, rec.y_m - T.y_m) < 0.005, tr["trial"]
            assert abs(np.rad2deg(wrap_angle(rec.yaw_rad - T.yaw_rad))) < 0.2, tr["trial"]
        assert abs(rec.clock_offset_s - T.clock_offset_s) < 0.5 * period, tr["trial"]
        # leg points at mocap frames vs the simulator's true leg centres
        legs = pd.read_parquet(out / "truth" / tr["trial"] / "legs.parquet")
        lp = leg_points(mocap, float(tr["sensor_height_m"]), sub, cfg)
        for j, side in enumerate("LR"):
            L = legs[legs.side == side].sort_values("t_s")
            fi = np.rint((L.t_s.to_numpy() - mocap.t[0]) * mocap.rate_hz).astype(int)
            err = np.linalg.norm(lp.xyz[fi, j, :2] - L[["x_m", "y_m"]].to_numpy(), axis=1)
            err = err[np.isfinite(err)]
            assert len(err) > 0.8 * len(L)
            if lp.source == "tibia_cylinder":
                # 4-marker cylinder: sub-mm marker noise levered to the scan height
                assert np.median(err) < 0.001 and np.percentile(err, 95) < 0.002, tr["trial"]
            else:
                assert err.max() < 0.002, tr["trial"]
        gt = ground_truth(mocap, scans, rec, tr, sub, cfg)
        assert len(gt) == 2 * scans.n_scans and gt.valid.mean() > 0.8
    assert n_checked >= 2


@pytest.mark.slow
def test_tiny_study_ultrasonic_acceptance(tiny):
    import json

    from gaitval.groundtruth import ground_truth
    from gaitval.io.c3d import read_c3d

    out, trials, _, cfg = tiny
    us = trials[trials.sensor_kind == "ultrasonic"]
    if us.empty:
        pytest.skip("the tiny preset has no ultrasonic trials")
    for tr in us.to_dict("records"):
        mocap = read_c3d(out / tr["mocap_file"])
        log = _read_us_log(out / tr["sensor_file"])
        meta = json.loads((out / "truth" / tr["trial"] / "meta.json").read_text())
        from gaitval.groundtruth import sensor_leg_points
        rec = register_trial(mocap, log, tr, None, cfg,
                             legs=sensor_leg_points(mocap, log, tr, None, cfg))
        assert abs(rec.clock_offset_s - meta["clock_offset_s"]) < 0.5 / log.rate_hz, tr["trial"]
        assert rec.pole_residual_m < 0.005
        gt = ground_truth(mocap, log, rec, tr, None, cfg)
        assert gt.valid.mean() > 0.9


def test_beam_bins_are_the_means_of_neighbouring_columns():
    """_bin (the clock estimate's 0.5 deg bins) gives numpy's reshape-mean bit for bit."""
    from gaitval.registration.clock import _bin

    rng = np.random.default_rng(3)
    for k in (1, 2, 3, 5, 7, 9):
        x = rng.random((50, 1081)) * rng.choice([1e-3, 1.0, 1e3], size=(50, 1081))
        n = 1081 // k * k
        assert np.array_equal(_bin(x, k), x[:, :n].reshape(50, -1, k).mean(axis=2))
