"""TUG evaluation rules (gaitval.evaluate.tug): phases, false tracking, stance matching."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import GaitvalError
from gaitval.evaluate.tug import (align_truth, evaluate_tug_trial, false_tracking,
                                  stance_failures, truth_stance_intervals, tug_phase_bounds,
                                  tug_phase_of)
from gaitval.methods import track_trial
from tug_synth import tug_scans

RATE = 40.0


def truth_frame(t, legs):
    return pd.concat([pd.DataFrame({"t_sensor_s": t, "side": s, "xs_m": legs[s][:, 0],
                                    "ys_m": legs[s][:, 1], "valid": True}) for s in "LR"],
                     ignore_index=True)


def static_frames(n=100):
    """Track frames with both legs standing at (1, ±0.1), truth identical, 40 Hz."""
    t = np.arange(n) / RATE
    rows = []
    for k in range(n):
        for s, y in (("L", 0.1), ("R", -0.1)):
            rows.append({"k": k, "t_sensor_s": t[k], "side": s, "x_m": 1.0, "y_m": y,
                         "xs_m": 1.0, "ys_m": y, "valid": True, "tug_phase": "turning",
                         "swing": False, "pattern": "SL"})
    return pd.DataFrame(rows)


@pytest.fixture(scope="module")
def synthetic():
    scans, legs = tug_scans(seed=5)
    return scans, truth_frame(scans.t, legs)


def test_tug_phase_bounds_bracket_the_turn(synthetic):
    _, truth = synthetic
    b = tug_phase_bounds(truth)
    # tug_synth: the body is on the half circle from about 3.75 s to 5.3 s
    assert 3.4 < b["t_turn_start_s"] < b["t_far_s"] < b["t_turn_end_s"] < 5.7
    lab = tug_phase_of(np.array([0.5, b["t_far_s"], 7.0]), b)
    assert lab.tolist() == ["forward", "turning", "return"]


def test_false_tracking_rule_by_hand():
    f = static_frames()
    sw = (f["side"] == "L") & f["k"].between(30, 45)           # 16 scans on the R leg
    f.loc[sw, "y_m"] = -0.1
    lost = (f["side"] == "R") & f["k"].between(60, 64)         # 5 scans 0.5 m off: too short
    f.loc[lost, "x_m"] = 1.5
    bad, ev = false_tracking(f)
    assert len(ev) == 1
    e = ev.iloc[0]
    assert (e.side, e.kind, e.k_start, e.k_end, e.tug_phase) == ("L", "swap", 30, 45, "turning")
    assert e.max_error_m == pytest.approx(0.2)
    assert bad.sum() == 16
    # long enough, the run is an event: "lost" while taking observations ...
    lost = (f["side"] == "R") & f["k"].between(60, 75)
    f.loc[lost, "x_m"] = 1.5
    f["observed"] = True
    _, ev = false_tracking(f)
    assert ev["kind"].tolist() == ["swap", "lost"]
    # ... "drift" when the leg was hidden (UO) and the prediction ran off
    f.loc[lost, "observed"] = False
    _, ev = false_tracking(f)
    assert ev["kind"].tolist() == ["swap", "drift"]


def test_legs_passing_each_other_is_not_false_tracking():
    f = static_frames()
    # the track is 8 cm off its own leg towards the other one: below swap_min_m = 0.10
    f.loc[(f["side"] == "L") & f["k"].between(10, 60), "y_m"] = 0.02
    _, ev = false_tracking(f)
    assert ev.empty


def test_stance_matching_rule():
    t = np.arange(0, 2.0, 1 / 200.0)
    x = np.where(t < 0.5, 0.0, np.where(t < 1.0, (t - 0.5) * 2.0, 1.0))   # stance-swing-stance
    truth = truth_frame(t, {"L": np.column_stack([x, 0.1 + 0 * t]),
                            "R": np.column_stack([0 * t, -0.1 + 0 * t])})
    st = truth_stance_intervals(truth)
    left = st[st.side == "L"]
    assert len(left) == 2
    assert left.t_end_s.iloc[0] == pytest.approx(0.5, abs=0.03)
    assert left.t_start_s.iloc[1] == pytest.approx(1.0, abs=0.03)
    # a tracker that says "swing" for the left leg during its second stance misses it
    tt = np.arange(0, 2.001, 1 / RATE)          # covers the truth (ends at 1.995 s)
    rows = []
    for k, ti in enumerate(tt):
        for s in "LR":
            rows.append({"k": k, "t_sensor_s": ti, "side": s, "valid": True,
                         "tug_phase": "forward", "swing": bool(s == "L" and ti > 0.6)})
    res = stance_failures(pd.DataFrame(rows), st)
    assert res[res.side == "L"]["identified"].tolist() == [True, False]
    assert res[res.side == "R"]["identified"].all()


@pytest.mark.parametrize("method", ["tug_m1", "tug_m2", "tug_m3"])
def test_clean_synthetic_tug_is_a_tracking_success(synthetic, method):
    scans, truth = synthetic
    ev = evaluate_tug_trial(track_trial(scans, method, 0.1), truth, trial="syn", method=method)
    s = ev["summary"].iloc[0]
    assert s.success and s.category == "success" and s.n_stance_true > 10
    f = ev["frames"][ev["frames"].valid]
    assert np.sqrt(np.mean(f.err_x_m ** 2)) < 0.05
    assert set(f.tug_phase) == {"forward", "turning", "return"}


def test_swapped_track_is_false_tracking_in_the_return_phase(synthetic):
    scans, truth = synthetic
    track = track_trial(scans, "tug_m3", 0.1)
    b = tug_phase_bounds(truth)
    late = track["t_sensor_s"] > b["t_turn_end_s"] + 0.5
    sw = track.copy()
    sw.loc[late, "side"] = sw.loc[late, "side"].map({"L": "R", "R": "L"})
    sw = sw.sort_values(["k", "side"], kind="stable").reset_index(drop=True)
    ev = evaluate_tug_trial(sw, truth, trial="syn", method="tug_m3")
    s = ev["summary"].iloc[0]
    assert not s.success and s.category == "false_tracking_return"
    assert set(ev["events"]["kind"]) == {"swap"} and set(ev["events"]["side"]) == {"L", "R"}


def test_align_truth_interpolates_and_flags_gaps():
    t = np.arange(0, 1.0, 0.005)
    legs = {"L": np.column_stack([t, 0 * t]), "R": np.column_stack([t, 0 * t - 0.2])}
    truth = truth_frame(t, legs)
    truth.loc[(truth.side == "L") & truth.t_sensor_s.between(0.5, 0.6), "valid"] = False
    track = pd.DataFrame({"k": [0, 0, 1, 1], "t_sensor_s": [0.1025, 0.1025, 0.55, 0.55],
                          "side": ["L", "R", "L", "R"], "x_m": [0.1, 0.1, 0.5, 0.5],
                          "y_m": [0.0, -0.2, 0.0, -0.2]})
    a = align_truth(track, truth)
    assert a["xs_m"].iloc[0] == pytest.approx(0.1025)
    assert a["err_x_m"].iloc[0] == pytest.approx(-0.0025)
    assert a["valid"].tolist() == [True, True, False, True]


def test_truth_without_required_columns_is_a_user_error():
    with pytest.raises(GaitvalError, match="lacks column"):
        tug_phase_bounds(pd.DataFrame({"t_sensor_s": [0.0], "side": ["L"]}))


def test_a_prediction_running_off_by_more_than_a_stride_is_lost():
    f = static_frames()
    f["observed"] = True
    run = (f["side"] == "R") & f["k"].between(20, 40)
    f.loc[run, "observed"] = False                   # hidden ...
    f.loc[run, "x_m"] = 1.5                          # ... 0.5 m off: drift
    _, ev = false_tracking(f)
    assert ev["kind"].tolist() == ["drift"]
    f.loc[run, "x_m"] = 2.5                          # 1.5 m off: the leg is lost
    _, ev = false_tracking(f)
    assert ev["kind"].tolist() == ["lost"]


# -- two judging rules side by side (issue 34) -----------------------------------------
def test_a_short_swap_fails_the_paper_rule_but_not_the_persistent_swap_rule():
    from gaitval.evaluate.tug import judged_false

    f = static_frames()
    f.loc[(f["side"] == "L") & f["k"].between(30, 45), "y_m"] = -0.1   # 16 scans = 0.40 s
    _, ev = false_tracking(f)
    assert ev["duration_s"].tolist() == [pytest.approx(0.40)]
    assert len(judged_false(ev, "paper")) == 1
    assert judged_false(ev, "persistent_swap").empty
    # 21 scans = 0.525 s > 0.5 s: false tracking under both rules
    f.loc[(f["side"] == "L") & f["k"].between(30, 50), "y_m"] = -0.1
    _, ev = false_tracking(f)
    assert len(judged_false(ev, "persistent_swap")) == 1
    # a lost event counts under both rules, however short
    g = static_frames()
    g["observed"] = True
    g.loc[(g["side"] == "R") & g["k"].between(60, 69), "x_m"] = 1.5     # 0.25 s
    _, ev = false_tracking(g)
    assert ev["kind"].tolist() == ["lost"]
    assert len(judged_false(ev, "persistent_swap")) == 1
    with pytest.raises(GaitvalError, match="judging rule"):
        judged_false(ev, "majority")


def test_the_summary_carries_both_rules(synthetic):
    scans, truth = synthetic
    track = track_trial(scans, "tug_m3", 0.1)
    b = tug_phase_bounds(truth)
    # the labels are swapped for 0.3 s in the return phase, then right again
    t0 = b["t_turn_end_s"] + 0.5
    brief = track["t_sensor_s"].between(t0, t0 + 0.3)
    sw = track.copy()
    sw.loc[brief, "side"] = sw.loc[brief, "side"].map({"L": "R", "R": "L"})
    sw = sw.sort_values(["k", "side"], kind="stable").reset_index(drop=True)
    s = evaluate_tug_trial(sw, truth, trial="syn", method="tug_m3")["summary"].iloc[0]
    assert s.category == "false_tracking_return" and not s.success
    assert s.category_persistent_swap == "success" and s.success_persistent_swap
    assert s.n_ft_events >= 1 and s.n_ft_events_persistent_swap == 0
