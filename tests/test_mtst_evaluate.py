"""MTST evaluation (seed 001 Tables 3-4): lost / false tracks against mocap and against the
rater's contacts — including a trial where the track follows the attendant — step matching,
the clock path of the annotations, and the bad inputs of issue 11 Scope 7."""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from mtst_synth import walk

from gaitval.errors import FileFormatError
from gaitval.evaluate.mtst import (check_annotations, match_contacts, to_sensor_clock)
from gaitval.evaluate.mtst_trial import evaluate_mtst_trial
from gaitval.evaluate.mtst_tracking import gate_usage, tracking_vs_truth
from gaitval.track.gate import VariableValidationRegion

STEPS = [(s, 0.4 * (i + 1), 0.1 if s == "L" else -0.1)
         for i, s in enumerate("LRLRLRLRLR")]
#: the attendant: 0.75 m to the participant's right, 0.25 m behind, quicker steps
ATTENDANT = [(s, 0.4 * (i + 1) - 0.25, (0.06 if s == "L" else -0.06) - 0.75)
             for i, s in enumerate("LRLRLRLRLRLRLR")]


def as_truth(tr: pd.DataFrame) -> pd.DataFrame:
    return pd.DataFrame({"t_sensor_s": tr["t_sensor_s"], "side": tr["side"],
                         "xs_m": tr["x_m"], "ys_m": tr["y_m"], "valid": True})


def as_track(tr: pd.DataFrame) -> pd.DataFrame:
    out = tr.copy()
    out["observed"] = True
    out["pattern"] = "SL"
    out["phase"] = 0
    out["interpolated"] = False
    return out


def annotations_of(tr: pd.DataFrame, *, cross_at: int | None = None):
    """Rater contacts at the start of each stance that follows a swing (sensor clock)."""
    rows = []
    for side, d in tr.groupby("side"):
        sw = d["swing"].to_numpy(bool)
        t = d["t_sensor_s"].to_numpy(float)
        for i in np.flatnonzero(sw[:-1] & ~sw[1:]) + 1:
            rows.append({"t_s": t[i], "event": "foot_contact", "side": side})
    ann = pd.DataFrame(rows).sort_values("t_s").reset_index(drop=True)
    if cross_at is not None:
        r = ann.iloc[cross_at]
        ann = pd.concat([ann, pd.DataFrame([{"t_s": r.t_s, "event": "cross_step",
                                             "side": r.side}])], ignore_index=True)
    for c in ("target", "value"):
        ann[c] = ""
    ann["rater"] = "R1"
    ann["t_mocap_s"] = ann["t_s"]
    return ann, {"time_base": "sensor"}


def evaluate(track, truth, ann):
    return evaluate_mtst_trial(track, trial="syn_t1", method="mtst_proposed", stick=False,
                               pose=(0.0, 0.0, 0.0), leg_width_m=0.1, height_m=1.6,
                               targets=None, annotations=ann, truth=truth,
                               gate=VariableValidationRegion())


def test_a_track_on_the_participant_is_a_success():
    tr = walk(STEPS)
    res = evaluate(as_track(tr), as_truth(tr), annotations_of(tr))
    s = res["summary"].iloc[0]
    assert s["category_mocap"] == "success" and s["category_annotations"] == "success"
    assert s["n_steps"] == len(STEPS) and s["non_detection"] == 0
    assert (res["steps"]["match"] >= 0).all()


def test_a_track_that_follows_the_attendant_is_a_false_track():
    """From 2 s on, the right-leg track leaves the participant for the attendant's right
    leg (observed all along): mocap calls it a false track following another object, and
    the rater's contacts see steps the participant did not take."""
    tr = walk(STEPS)
    att = walk(ATTENDANT, step_s=0.35, stand_s=0.15,
               start={"L": (-0.25, -0.69), "R": (-0.25, -0.81)})
    track = as_track(tr)
    a = att[att["side"] == "R"].set_index("k")
    switch = track["t_sensor_s"] >= 2.0
    rows = switch & (track["side"] == "R") & track["k"].isin(a.index)
    for col in ("x_m", "y_m", "vx_mps", "vy_mps", "swing"):
        track.loc[rows, col] = a.loc[track.loc[rows, "k"], col].to_numpy()
    res = evaluate(track, as_truth(tr), annotations_of(tr))
    s = res["summary"].iloc[0]
    assert s["category_mocap"] == "false_other"
    ev = res["events"]
    first = ev[ev["reference"] == "mocap"].iloc[0]
    assert first["side"] == "R" and first["t_start_s"] == pytest.approx(2.0, abs=0.3)
    assert s["category_annotations"] in ("false_other", "lost")


def test_swapped_tracks_are_false_swaps():
    tr = walk(STEPS)
    track = as_track(tr)
    late = track["t_sensor_s"] >= 2.0
    track.loc[late, "side"] = track.loc[late, "side"].map({"L": "R", "R": "L"})
    track = track.sort_values(["k", "side"]).reset_index(drop=True)
    res = evaluate(track, as_truth(tr), annotations_of(tr))
    s = res["summary"].iloc[0]
    assert s["category_mocap"] == "false_swap"
    assert s["category_annotations"] == "false_swap"


def test_a_prediction_that_runs_off_unobserved_is_lost():
    tr = walk(STEPS)
    truth = as_truth(tr)
    track = as_track(tr)
    off = (track["side"] == "L") & (track["t_sensor_s"] >= 2.0)
    track.loc[off, "x_m"] = track.loc[off, "x_m"].iloc[0] - 0.5 * (
        track.loc[off, "t_sensor_s"] - 2.0)                 # drifts back, hidden
    track.loc[off, ["observed", "pattern"]] = [False, "UO"]
    cat, ev = tracking_vs_truth(track, truth)
    assert cat == "lost" and ev.iloc[0]["side"] == "L"


def test_contacts_match_within_a_stride_not_across_legs():
    contacts = pd.DataFrame({"side": ["L", "R", "L"], "t_sensor_s": [1.3, 1.9, 2.5]})
    ann = pd.DataFrame({"side": ["L", "R", "L", "R"], "t_ann_s": [1.0, 1.6, 2.2, 2.8]})
    match, other = match_contacts(contacts, ann, 0.15)
    assert list(match) == [0, 1, 2, -1]          # each system contact 0.3 s into its stride
    assert list(other) == [-1, -1, -1, -1]      # and half a stride from the other leg's


def test_annotation_clock_goes_through_the_trials_offset():
    ann = pd.DataFrame({"t_s": [1.0, 2.0], "t_mocap_s": [0.5, 1.5]})
    t = to_sensor_clock(ann, {"time_base": "video", "time_offset_s": "-0.5"}, 1.2, 100.0)
    assert t == pytest.approx([1.2 + 1.0001 * 0.5, 1.2 + 1.0001 * 1.5])
    assert to_sensor_clock(ann, {"time_base": "sensor"}, None) == pytest.approx([1.0, 2.0])
    with pytest.raises(FileFormatError, match=r"trial T1.*no clock offset"):
        to_sensor_clock(ann, {"time_base": "video"}, None, path="a.csv", trial="T1")


def test_unknown_event_types_name_the_file_and_trial():
    ann = pd.DataFrame({"t_s": [1.0], "event": ["heel_rise"], "side": ["L"], "target": [""],
                        "value": [""]})
    with pytest.raises(FileFormatError, match=r"\[file x/a.annotations.csv, trial T1\] "
                                              r"unknown annotation event type"):
        check_annotations(ann, path="x/a.annotations.csv", trial="T1")


def test_annotation_times_outside_the_trial_are_refused():
    tr = walk(STEPS)
    ann, meta = annotations_of(tr)
    ann.loc[0, ["t_s", "t_mocap_s"]] = 99.0
    with pytest.raises(FileFormatError, match="outside the trial"):
        evaluate_mtst_trial(as_track(tr), trial="T1", method="m", stick=False,
                            pose=(0, 0, 0), leg_width_m=0.1, height_m=1.6, targets=None,
                            annotations=(ann, meta), annotation_path="a.csv")


def test_gate_usage_reports_the_table1_cell_of_every_scan():
    tr = as_track(walk(STEPS))
    tr.loc[(tr.side == "R") & tr.k.between(20, 22), "pattern"] = "UO"
    g = gate_usage(tr, 0.1)
    assert set(g["cell"]) <= {"stance_observable", "stance_unobservable",
                              "swing_observable", "swing_unobservable"}
    r = g[(g.side == "R") & (g.k == 23)].iloc[0]
    assert r["cell"].endswith("_unobservable")              # H = 3 up to k−1 = 22
    assert (g["radius_leg_widths"] >= 0.75).all()


def test_a_brief_swap_is_forgiven_only_by_the_persistent_swap_rule():
    """Issue 34: the labels swap for 0.3 s and swap back; the paper rule (mocap) calls it
    a false track, the persistent-swap rule (> 0.5 s) does not; a lasting swap fails both."""
    tr = walk(STEPS)

    def swapped(t0, t1):
        track = as_track(tr)
        w = track["t_sensor_s"].between(t0, t1)
        track.loc[w, "side"] = track.loc[w, "side"].map({"L": "R", "R": "L"})
        return track.sort_values(["k", "side"]).reset_index(drop=True)

    s = evaluate(swapped(2.0, 2.3), as_truth(tr), annotations_of(tr))["summary"].iloc[0]
    assert s["category_mocap"] == "false_swap"
    assert s["category_mocap_persistent_swap"] == "success"
    s = evaluate(swapped(2.0, 10.0), as_truth(tr), annotations_of(tr))["summary"].iloc[0]
    assert s["category_mocap"] == s["category_mocap_persistent_swap"] == "false_swap"
