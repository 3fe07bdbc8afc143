"""Ground truth: joint centres, leg point at sensor height, tibia cylinder, gaps, filters,
resampling to sensor timestamps; and behaviour on real C3D walks."""
from __future__ import annotations

import numpy as np
import pytest

from gaitval.errors import MarkerError
from gaitval.groundtruth import (GT_COLUMNS, fill_short_gaps, fit_cylinder, ground_truth,
                                 leg_points, point_at_height)
from gaitval.groundtruth.filters import differentiate, lowpass
from gaitval.groundtruth.joints import joint_centre
from gaitval.registration import RegistrationRecord
from gaitval.types import MocapTrial

from test_registration import (H, POSE, SUBJECT, TRIAL, legs_xy, synthetic_mocap,
                               synthetic_scans)


# ---------------------------------------------------------------------------------------
# hand-computable pieces
# ---------------------------------------------------------------------------------------
def test_point_at_height_hand_case():
    knee = np.array([[0.0, 0.0, 0.5], [0.0, 0.0, 0.5]])
    ankle = np.array([[0.1, 0.2, 0.1], [0.0, 0.0, 0.45]])      # 2nd: shank near horizontal
    p, ok = point_at_height(knee, ankle, 0.3)
    # s = (0.3 - 0.1) / (0.5 - 0.1) = 0.5 -> halfway
    assert p[0] == pytest.approx([0.05, 0.1, 0.3])
    assert ok.tolist() == [True, False] and np.isnan(p[1]).all()


def test_fill_short_gaps_cubic_exact_and_long_gap_kept():
    rate = 100.0
    t = np.arange(60) / rate
    x = np.column_stack([2 * t ** 3 - t ** 2 + 0.5, np.sin(t), t])
    y = x.copy()
    y[10:15] = np.nan          # 5 frames = 0.05 s: filled
    y[30:45] = np.nan          # 15 frames = 0.15 s: kept
    y[:2] = np.nan             # leading: kept
    f, filled = fill_short_gaps(y, rate, max_gap_s=0.10)
    assert filled.sum() == 5 and filled[10:15].all()
    # a cubic spline through samples of a cubic polynomial reproduces it
    assert f[10:15, 0] == pytest.approx(x[10:15, 0], abs=1e-9)
    assert np.isnan(f[30:45]).all() and np.isnan(f[:2]).all()


def test_lowpass_and_differentiate():
    rate = 200.0
    t = np.arange(0, 5, 1 / rate)
    x = np.sin(2 * np.pi * 1.0 * t) + 0.05 * np.sin(2 * np.pi * 40 * t)
    xf = lowpass(x, rate, 10.0, 2)
    # 40 Hz attenuated by |H|^2 of a 2nd-order Butterworth at 4 fc: 1/(1+4^4)^... < 1 %
    mid = slice(100, -100)
    assert np.abs(xf - np.sin(2 * np.pi * t))[mid].max() < 0.01
    v = differentiate(xf, t)
    assert np.abs(v - 2 * np.pi * np.cos(2 * np.pi * t))[mid].max() < 0.05 * 2 * np.pi


def test_cylinder_fit_constructed():
    """Four markers 9 mm outside a 50 mm-radius tilted shank: axis and radius recovered."""
    n = 50
    rng = np.random.default_rng(0)
    tilt = np.deg2rad(np.linspace(-20, 25, n))
    d = np.column_stack([np.sin(tilt), np.zeros(n), np.cos(tilt)])   # axis direction
    ankle = np.column_stack([np.linspace(0, 1, n), np.full(n, 0.1), np.full(n, 0.08)])
    e1 = np.column_stack([np.cos(tilt), np.zeros(n), -np.sin(tilt)])
    e2 = np.tile([0.0, 1.0, 0.0], (n, 1))
    R = 0.05 + 0.009
    markers = []
    for s, phi in ((0.15, 0.3), (0.25, 1.9), (0.2, 3.4), (0.3, 4.8)):
        markers.append(ankle + s * d + R * (np.cos(phi) * e1 + np.sin(phi) * e2))
    M = np.stack(markers, axis=1) + rng.normal(0, 1e-5, (n, 4, 3))
    cen, dd, skin = fit_cylinder(M, d)
    assert skin == pytest.approx(0.05, abs=2e-4)
    # axis point at h equals the ankle->knee line point at h
    from gaitval.groundtruth import cylinder_at_height
    p, ok = cylinder_at_height(cen, dd, 0.27)
    ref, _ = point_at_height(ankle + 0.4 * d, ankle, 0.27)
    assert ok.all() and np.abs(p - ref).max() < 2e-4


def _trial_with(labels_xyz, rate=100.0):
    labels = list(labels_xyz)
    return MocapTrial("m.c3d", rate, 1, labels, np.stack([labels_xyz[k] for k in labels], 1))


def test_joint_centre_preference_and_lateral_offset():
    n = 5
    one = lambda x, y, z: np.tile([x, y, z], (n, 1))
    base = {"LKNE": one(0, 0.20, 0.5), "RKNE": one(0, -0.20, 0.5),
            "LASI": one(0, 0.12, 0.9), "RASI": one(0, -0.12, 0.9)}
    # lateral offset: medial for L is towards RASI (-y); half of knee width 0.10 m
    m = _trial_with(base)
    p, src = joint_centre(m, "L", "knee", {"knee_width_m": 0.10})
    assert src == "lateral_offset" and p[0] == pytest.approx([0, 0.15, 0.5])
    p, src = joint_centre(m, "R", "knee", {"knee_width_m": 0.10})
    assert p[0] == pytest.approx([0, -0.15, 0.5])
    with pytest.raises(MarkerError, match="knee_width_m"):
        joint_centre(m, "L", "knee", {})
    # medial marker beats the offset
    m = _trial_with({**base, "LKNEin": one(0, 0.10, 0.5)})
    p, src = joint_centre(m, "L", "knee", {"knee_width_m": 0.10})
    assert src == "lateral_medial_midpoint" and p[0] == pytest.approx([0, 0.15, 0.5])
    # explicit joint centre beats the midpoint, PiG bone output beats both
    m = _trial_with({**base, "LKNEin": one(0, 0.10, 0.5), "LKJC": one(0, 0.16, 0.5)})
    assert joint_centre(m, "L", "knee")[1] == "joint_centre_markers"
    m = _trial_with({**base, "LKJC": one(0, 0.16, 0.5), "LFEO": one(0, 0.155, 0.5)})
    p, src = joint_centre(m, "L", "knee")
    assert src == "pig_bone_outputs" and p[0, 1] == pytest.approx(0.155)


# ---------------------------------------------------------------------------------------
# ground truth at sensor timestamps (constructed walker)
# ---------------------------------------------------------------------------------------
def test_leg_points_computed_once_per_trial(monkeypatch):
    """The pipeline's order (gaitval.pipeline.steps.register.register_step): leg points
    once, handed to the registration and then to the ground truth, which gives the same
    table as computing them itself."""
    import gaitval.groundtruth.legs as legs_mod
    from gaitval.groundtruth import sensor_leg_points
    from gaitval.registration import register_trial

    mocap, scans = synthetic_mocap(), synthetic_scans()
    calls = []
    real = legs_mod.leg_points
    monkeypatch.setattr(legs_mod, "leg_points", lambda *a, **k: calls.append(1) or real(*a, **k))
    legs = sensor_leg_points(mocap, scans, TRIAL, SUBJECT, {})
    reg = register_trial(mocap, scans, TRIAL, SUBJECT, {}, legs=legs)
    gt = ground_truth(mocap, scans, reg, TRIAL, SUBJECT, {}, legs=legs)
    assert len(calls) == 1
    assert reg.joint_centre_source == legs.source and reg.gt_frames_excluded == legs.n_excluded
    assert gt.equals(ground_truth(mocap, scans, reg, TRIAL, SUBJECT, {}))
    assert len(calls) == 2          # without legs the ground truth computes its own


def test_ground_truth_at_sensor_timestamps():
    mocap = synthetic_mocap()
    scans = synthetic_scans()
    reg = RegistrationRecord("T01", *POSE, 2.345, 0.0, 0.001, 0.9, "pig_bone_outputs", 0)
    gt = ground_truth(mocap, scans, reg, TRIAL, SUBJECT, {})
    assert list(gt.columns) == GT_COLUMNS
    assert len(gt) == 2 * scans.n_scans and gt.valid.mean() > 0.95
    v = gt[gt.valid]
    t_m = v.t_mocap_s.to_numpy()
    assert v.t_sensor_s.to_numpy() - t_m == pytest.approx(2.345)
    truth = legs_xy(t_m)
    j = (v.side == "R").to_numpy().astype(int)
    xy_true = truth[np.arange(len(v)), j]
    # linear interpolation of a 200 Hz trajectory: sub-millimetre
    assert np.abs(v[["x_m", "y_m"]].to_numpy() - xy_true).max() < 1e-3
    # sensor-frame coordinates are the field ones mapped through the pose
    from gaitval.registration.rigid import field_to_sensor
    assert v[["xs_m", "ys_m"]].to_numpy() == pytest.approx(field_to_sensor(xy_true, *POSE), abs=1e-3)
    # velocity: analytic v(1 - cos(w t)) for the left leg while walking
    w = 2 * np.pi * 0.9
    vl = v[(v.side == "L") & (v.t_mocap_s > 1.0) & (v.t_mocap_s < 3.5)]
    ref = 1.0 * (1 - np.cos(w * (vl.t_mocap_s - 0.5)))
    assert np.abs(vl.vx_mps - ref).max() < 0.05


# ---------------------------------------------------------------------------------------
# real C3D walks (../shared/realdata/c3d)
# ---------------------------------------------------------------------------------------
def _load(realdata, name):
    from gaitval.io.c3d import read_c3d
    return read_c3d(realdata / "c3d" / f"{name}.c3d")


def _rotated(m: MocapTrial, deg: float) -> MocapTrial:
    a = np.deg2rad(deg)
    R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
    return MocapTrial(m.path, m.rate_hz, m.first_frame, list(m.labels), m.xyz @ R.T)


REAL_WALKS = ["FunctionalWalk", "PiG_Motion-FlatFoot-Full", "PiG_Motion-FlatFoot-Hole",
              "opensim_walking2"]


@pytest.mark.realdata
@pytest.mark.parametrize("name,rot", [(n, 0.0) for n in REAL_WALKS] + [("FunctionalWalk", 90.0),
                                                                       ("PiG_Motion-FlatFoot-Full", -90.0)])
def test_real_walk_shin_points(realdata, name, rot):
    """Projected shin points: at the requested height, progressing with the walk,
    alternating stance and swing, left leg on the walker's left."""
    m = _load(realdata, name)
    if rot:
        # No file in realdata walks along Y (all walk along +X or -X, checked), so the
        # along-Y case is the same walk turned about the vertical axis.
        m = _rotated(m, rot)
    h = 0.27
    lp = leg_points(m, h, {"knee_width_m": 0.10, "ankle_width_m": 0.07})
    ok = lp.valid
    assert ok.any(axis=0).all()
    z = lp.xyz[..., 2][ok]
    assert z == pytest.approx(np.full(z.shape, h), abs=1e-9)
    xy = lp.xyz[..., :2]
    # walking direction from the valid leg points (start -> end of the mean of both legs)
    both = ok.all(axis=1)
    mid = xy[both].mean(axis=1)
    d = mid[-1] - mid[0]
    assert np.linalg.norm(d) > 1.5                                      # walked > 1.5 m
    d = d / np.linalg.norm(d)
    if rot == 90.0:
        assert abs(d[1]) > 0.95                                         # along +Y indeed
    # progression: each leg's along-track coordinate never goes back by more than 2 cm
    for j in range(2):
        s = xy[ok[:, j], j] @ d
        assert np.all(np.diff(s) > -0.02)
        assert s[-1] - s[0] > 1.0
    # stance and swing alternate: in stance the shin only rolls over the ankle (slower than
    # half the walking speed), in swing it moves at several times the walking speed
    both_idx = np.flatnonzero(both)
    v_walk = np.linalg.norm(mid[-1] - mid[0]) / ((both_idx[-1] - both_idx[0]) / m.rate_hz)
    with np.errstate(invalid="ignore"):
        speed = np.linalg.norm(np.gradient(lowpass(xy, m.rate_hz, 6.0), axis=0),
                               axis=2) * m.rate_hz
        stance = speed < 0.5 * v_walk
        swing = speed > 1.5 * v_walk
    for j in range(2):
        sel = ok[:, j] & np.isfinite(speed[:, j])
        assert 0.25 < stance[sel, j].mean() < 0.75
        assert swing[sel, j].mean() > 0.1
        assert np.nanmax(speed[sel, j]) > 2.0 * v_walk
    sel = both & np.isfinite(speed).all(axis=1)
    assert np.mean(swing[sel, 0] & swing[sel, 1]) < 0.05               # never both swinging
    # one leg always supports: the slower shin moves slower than the body
    assert np.mean(speed[sel].min(axis=1) < v_walk) > 0.9
    # left leg on the left of the walking direction (cross product > 0)
    lat = (xy[both, 0] - xy[both, 1]) @ np.array([-d[1], d[0]])
    assert np.median(lat) > 0.03


@pytest.mark.realdata
def test_real_joint_centre_sources(realdata):
    assert leg_points(_load(realdata, "FunctionalWalk"), 0.27).source == "pig_bone_outputs"
    assert leg_points(_load(realdata, "opensim_walking2"), 0.27).source == "joint_centre_markers"


@pytest.mark.realdata
@pytest.mark.parametrize("name", ["c3dorg_sample09_PlugInC3D", "opensim_walking2",
                                  "PiG_Motion-FlatFoot-Hole"])
def test_real_gap_frames_counted(realdata, name):
    """Excluded frames = frames where a used joint-centre marker is still missing after
    filling; with filling disabled, exactly the frames with any raw gap in those markers."""
    m = _load(realdata, name)
    used = [lb for lb in ("LFEO", "LTIO", "RFEO", "RTIO") if m.has(lb)] or \
        [lb for lb in ("LKJC", "LAJC", "RKJC", "RAJC") if m.has(lb)]
    raw_missing = np.zeros(m.n_frames, dtype=bool)
    for lb in used:
        raw_missing |= ~np.isfinite(m.marker(lb)).all(axis=1)
    nofill = leg_points(m, 0.27, cfg={"max_gap_s": 0.0})
    assert nofill.n_excluded >= raw_missing.sum()
    # frames with all markers present are never excluded except for the height rule
    assert nofill.n_excluded - raw_missing.sum() <= 0.02 * m.n_frames
    filled = leg_points(m, 0.27)
    assert filled.n_excluded <= nofill.n_excluded
    if name == "PiG_Motion-FlatFoot-Hole":
        # Finding: this file's ~10 % missing samples are all in Nexus' kinetic outputs
        # (powers, forces, moments), none in the leg markers or bone outputs.
        assert raw_missing.sum() == 0 and filled.n_excluded == 0
        assert (~np.isfinite(m.xyz).all(axis=2)).mean() > 0.09
    else:
        assert filled.n_excluded > 0
