"""Leg detection: edges (eq. 6), the five leg patterns (seed 001 §2.3), background removal."""
from __future__ import annotations

import math

import numpy as np
import pytest

from gaitval.detect import BACKGROUNDS, DETECTORS, split_observations
from gaitval.detect.legpatterns import (classify_segment, detect_scan, edges,
                                        see_through_occluders)
from gaitval.errors import GaitvalError
from gaitval.types import ScanSeries
from tug_synth import raycast, tug_scans

W = 0.10                      # leg width w_l
ANG = -np.deg2rad(135) + np.deg2rad(0.25) * np.arange(1081)


def scan_of(*centres, radius=W / 2, noise=0.0):
    """One noise-free scan (no background) of circles at the given (x, y) centres."""
    r = raycast(np.zeros(1), [np.array([c]) for c in centres], radius, noise_m=noise,
                background=False)[0]
    return r


def test_edges_labels_follow_eq6():
    # l_i > l_{i+1} → e^B = i, e^F = i+1 ; l_i < l_{i+1} → e^F = i, e^B = i+1
    l = np.array([5.0, 5.0, 2.0, 2.0, 2.0, 5.0, 5.0])
    assert edges(l, W) == [(1, "B"), (2, "F"), (4, "F"), (5, "B")]
    # a jump of exactly w_l/2 is not an edge (strict inequality), w_l/2 + 1 mm is
    assert edges(np.array([2.0, 2.05, 2.0]), W) == []
    assert edges(np.array([2.0, 2.051]), W) == [(0, "F"), (1, "B")]
    # no return counts as infinitely far
    assert edges(np.array([np.nan, 2.0, np.inf]), W) == [(0, "B"), (1, "F"), (1, "F"), (2, "B")]


@pytest.mark.parametrize("near_l, near_r, width, expected", [
    (True, True, 0.10, "SL"), (True, True, 0.15, "SL"), (True, True, 0.02, None),
    (True, True, 0.20, "LT"), (True, True, 0.31, None),
    (False, True, 0.08, "FS_O"), (True, False, 0.05, "FS_O"), (True, False, 0.04, "FS_U"),
    (False, True, 0.021, "FS_U"), (False, True, 0.02, None), (False, True, 0.2, "LT"),
    (False, False, 0.10, None),
])
def test_width_conditions_of_seed001(near_l, near_r, width, expected):
    assert classify_segment(near_l, near_r, width, W) == expected


def test_fs_u_can_be_switched_off():
    assert classify_segment(True, False, 0.04, W, use_fs_u=False) is None


def test_sl_single_leg_position():
    r = scan_of((2.0, 0.3))
    obs = detect_scan(r, ANG, W)
    assert [o[2] for o in obs] == ["SL"]
    assert math.hypot(obs[0][0] - 2.0, obs[0][1] - 0.3) < 0.01


def test_lt_two_legs_side_by_side():
    # shanks pressed together (centres 0.08 m apart): no edge between them
    r = scan_of((2.0, 0.04), (2.0, -0.04))
    obs = detect_scan(r, ANG, W)
    assert [o[2] for o in obs] == ["LT", "LT"]
    # right to left: the first observation is the right-hand leg (y < 0)
    assert obs[0][1] < obs[1][1]
    for o, c in zip(obs, [(2.0, -0.04), (2.0, 0.04)]):
        assert math.hypot(o[0] - c[0], o[1] - c[1]) < 0.03


def test_fs_o_partly_hidden_leg_is_observed():
    # near leg at 1.5 m; far leg at 2.0 m offset so that about 70 % of it is visible
    near, far = (1.5, 0.0), (2.0, 0.10)
    obs = detect_scan(scan_of(near, far), ANG, W)
    pats = sorted(o[2] for o in obs)
    assert pats == ["FS_O", "SL"]
    fs = [o for o in obs if o[2] == "FS_O"][0]
    assert math.hypot(fs[0] - far[0], fs[1] - far[1]) < 0.04


def test_fs_u_sliver_gives_a_virtual_position():
    near, far = (1.5, 0.0), (2.0, 0.052)     # only a sliver (≈0.35 w_l) of the far leg
    obs = detect_scan(scan_of(near, far), ANG, W)
    fsu = [o for o in obs if o[2] == "FS_U"]
    assert len(fsu) == 1
    assert math.hypot(fsu[0][0] - far[0], fsu[0][1] - far[1]) < 0.04
    # the conventional detector does not report it
    assert [o[2] for o in detect_scan(scan_of(near, far), ANG, W, use_fs_u=False)] == ["SL"]


def test_uo_fully_hidden_leg_gives_no_observation():
    obs = detect_scan(scan_of((1.5, 0.0), (2.0, 0.0)), ANG, W)
    assert [o[2] for o in obs] == ["SL"]


def test_wide_objects_are_not_legs():
    r = np.full(1081, np.inf)
    r[500:560] = 2.0                              # 0.5 m wide: > 3 w_l
    assert detect_scan(r, ANG, W) == []


def test_background_model_keeps_legs_and_drops_walls_and_poles():
    scans, truth = tug_scans(seed=3)
    obs = DETECTORS.build("leg_patterns").detect(scans, W)
    k = obs["k"].to_numpy()
    d = np.minimum(np.hypot(obs.x_m - truth["L"][k, 0], obs.y_m - truth["L"][k, 1]),
                   np.hypot(obs.x_m - truth["R"][k, 0], obs.y_m - truth["R"][k, 1]))
    assert (d < 0.10).mean() > 0.99               # observations are legs
    # both legs are seen in most scans
    per_scan = obs.groupby("k").size().reindex(range(scans.n_scans), fill_value=0)
    assert (per_scan >= 2).mean() > 0.8
    # without background removal the chair legs, the pole and walls show up as "legs"
    raw = DETECTORS.build({"name": "leg_patterns", "background": "none"}).detect(scans, W)
    assert len(raw) > len(obs)


def test_percentile_background_per_beam():
    r = np.array([[1.0, np.nan], [1.0, np.nan], [0.5, 3.0], [1.0, np.nan]])
    bg = BACKGROUNDS.build({"name": "percentile", "q": 95.0, "margin_m": 0.1})
    np.testing.assert_array_equal(bg.model(r), [1.0, np.inf])
    m = bg.mask(r)
    assert m[2, 0] == 0.5 and m[2, 1] == 3.0       # in front of the background
    assert np.isinf(m[0, 0]) and np.isinf(m[0, 1])  # the background itself / no return


def test_observation_table_columns_and_split():
    scans, _ = tug_scans(seed=1)
    obs = DETECTORS.build("leg_patterns").detect(scans, W)
    assert list(obs.columns) == ["k", "t_sensor_s", "j", "x_m", "y_m", "pattern", "width_m",
                                 "i_first", "i_last"]
    assert set(obs["pattern"]) <= {"SL", "LT", "FS_O", "FS_U"}
    xy, pats = split_observations(obs, scans.n_scans)
    assert len(xy) == scans.n_scans and sum(len(p) for p in pats) == len(obs)


def test_implausible_leg_width_is_a_user_error():
    scans, _ = tug_scans(seed=1)
    with pytest.raises(GaitvalError, match="leg width"):
        DETECTORS.build("leg_patterns").detect(scans, 100.0)


@pytest.mark.parametrize("name", DETECTORS.names())
def test_detector_contract(name):
    """Every registered detector: empty scans → empty table; a lone leg → one row."""
    import inspect
    takes_bg = "background" in inspect.signature(DETECTORS[name]).parameters
    det = DETECTORS.build({"name": name, **({"background": "none"} if takes_bg else {})})
    r = np.full((3, 1081), np.nan)
    r[1] = scan_of((1.0, 0.0))
    s = ScanSeries(t=np.arange(3) * 0.025, ranges=r, angle_min=ANG[0],
                   angle_increment=ANG[1] - ANG[0], range_min=0.1, range_max=30.0)
    obs = det.detect(s, W)
    assert obs["k"].tolist() == [1]
    assert abs(obs["x_m"].iloc[0] - 1.0) < 0.02 and obs["t_sensor_s"].iloc[0] == 0.025


def test_real_bag_scans_do_not_crash(realdata):
    """Real ROS LaserScan data (leg_tracker demo: inf returns, 10 Hz): finite legs found."""
    from gaitval.io.rosbag import read_rosbag_scans

    s = read_rosbag_scans(realdata / "lrs" / "demo_stationary_simple_environment.bag",
                          "/scan")
    obs = DETECTORS.build("leg_patterns").detect(s, W)
    assert len(obs) > 0
    assert np.isfinite(obs[["x_m", "y_m"]].to_numpy()).all()
    assert (np.hypot(obs.x_m, obs.y_m) <= s.range_max + W).all()


def test_one_leg_cut_by_an_occluder_gives_one_observation():
    # a thin pole (r = 1.5 cm, background) 0.3 m straight in front of a leg at 1.3 m
    leg = scan_of((1.3, 0.0))
    pole = raycast(np.zeros(1), [np.array([[1.0, 0.0]])], 0.015, noise_m=0.0,
                   background=False)[0]
    in_front = np.isfinite(pole) & (pole < leg)
    masked = np.where(in_front, np.inf, leg)           # the pole removed as background
    # without help the leg falls into two SL pieces 7 cm apart: one of them is kept
    obs = detect_scan(masked, ANG, W)
    assert len(obs) == 1 and math.hypot(obs[0][0] - 1.3, obs[0][1]) < 0.04
    # seeing through the pole restores the whole leg
    raw = np.where(in_front, pole, leg)
    filled = see_through_occluders(masked, raw, ANG, W)
    obs = detect_scan(filled, ANG, W)
    assert [o[2] for o in obs] == ["SL"] and math.hypot(obs[0][0] - 1.3, obs[0][1]) < 0.01
