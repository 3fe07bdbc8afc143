"""Issue 18: hand-annotated real laser recordings, CLEAR-MOT through py-motmetrics.

The CLEAR-MOT numbers of the constructed sequence below are worked out by hand from the
definitions (Bernardin & Stiefelhagen 2008; Ristani et al. 2016 for IDF1), not from
motmetrics, and the real bag's annotation counts come from ../shared/realdata/README.md.
"""
from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import ConfigError, FileFormatError
from gaitval.evaluate.clearmot import (assign_scans, clear_mot, false_leg_tracks,
                                       person_hypotheses)
from gaitval.io.annotations_bag import (read_bag_annotations, read_position_csv,
                                        write_position_csv)
from gaitval.track import INITIALISERS
from gaitval.track.observations import DetectionSeries

BAG = "lrs/person_following_outdoor_1.bag"


# -- the real annotated bag ------------------------------------------------------------------
@pytest.fixture(scope="module")
def outdoor(realdata):
    path = realdata / BAG
    if not path.is_file():
        pytest.skip(f"{path} is absent")
    return path, read_bag_annotations(path, "/ground_truth_people_tracks", "/scan_base2")


@pytest.mark.realdata
def test_bag_annotations_are_read_per_scan(outdoor):
    _, (ann, meta) = outdoor
    # realdata README: 6,179 annotated positions of one person, id 2, on 7,170 scans
    assert len(ann) == 6179 and meta["n_messages"] == 6179
    assert meta["ids"] == ["2"] and meta["msgtype"] == "leg_tracker/msg/Person"
    assert meta["n_before_first_scan"] == 0
    # one annotation per annotated scan, every index a scan of /scan_base2
    assert ann["k"].is_unique and ann["k"].min() >= 0 and ann["k"].max() < 7170
    # Person has no header: the frame comes from the annotation tool's display markers
    assert meta["frame"] == "base_laser_link"
    assert meta["frame_source"].startswith("ground_truth_people_tracks_markers")
    # the person is in front of the laser (field of view -34.4..+51.4 deg, <= 5.6 m)
    bearing = np.degrees(np.arctan2(ann["y_m"], ann["x_m"]))
    r = np.hypot(ann["x_m"], ann["y_m"])
    assert bearing.min() > -40 and bearing.max() < 57 and r.max() < 5.6


@pytest.mark.realdata
def test_bag_annotation_times_are_the_scans_header_stamps(outdoor):
    from gaitval.io.rosbag import read_rosbag_scans
    path, (ann, _) = outdoor
    scans = read_rosbag_scans(path, "/scan_base2")
    assert np.array_equal(ann["t_s"].to_numpy(), scans.t[ann["k"].to_numpy()])


@pytest.mark.realdata
def test_bag_without_annotation_topic_is_one_clear_error(realdata):
    path = realdata / "lrs" / "positive_1.bag"
    with pytest.raises(FileFormatError, match="annotation topic") as e:
        read_bag_annotations(path, None, "right_scan", trial="t1")
    assert "positive_1.bag" in str(e.value) and "t1" in str(e.value)
    with pytest.raises(FileFormatError, match="is not in this bag"):
        read_bag_annotations(path, "/people", "right_scan")


# -- CLEAR-MOT of a constructed tracker output, computed by hand ------------------------------
def _sequence():
    """One annotated person A at the origin on frames 0, 1, 2, 4, 5, 6, 7 (none on 3)."""
    gt = pd.DataFrame({"k": [0, 1, 2, 4, 5, 6, 7], "id": "A", "x_m": 0.0, "y_m": 0.0})
    hyp = pd.DataFrame([
        (0, 1, 0.1, 0.0),    # match, 0.1 m
        (1, 1, 0.2, 0.0),    # match, 0.2 m
        (2, 1, 0.8, 0.0),    # 0.8 m >= 0.75 m: a miss (FN) and a false positive
        (3, 1, 5.0, 5.0),    # nobody annotated: false positive
        (4, 2, 0.3, 0.0),    # match by a new hypothesis: one ID switch, 0.3 m
        (5, 2, 0.0, 0.4),    # match, 0.4 m
        (5, 3, 3.0, 0.0),    # a second hypothesis far away: false positive
        (6, 2, 0.0, 0.5),    # match, 0.5 m
        (7, 2, 0.1, 0.0),    # match, 0.1 m
    ], columns=["k", "hyp_id", "x_m", "y_m"])
    return gt, hyp


def test_clear_mot_matches_hand_computed_values():
    gt, hyp = _sequence()
    s, events = clear_mot(gt, hyp, n_frames=8, match_m=0.75)
    # GT = 7 objects; FN = 1 (frame 2); FP = 3 (frames 2, 3, 5); IDSW = 1 (frame 4);
    # 6 matched pairs, of which motmetrics counts the switching one as SWITCH, not MATCH
    assert (s["gt"], s["fn"], s["fp"], s["idsw"], s["matches"]) == (7, 1, 3, 1, 5)
    # MOTA = 1 - (FN + FP + IDSW) / GT = 1 - 5/7
    assert s["mota"] == pytest.approx(2 / 7)
    # MOTP = mean matched distance = (0.1 + 0.2 + 0.3 + 0.4 + 0.5 + 0.1) / 6 m
    assert s["motp_m"] == pytest.approx(1.6 / 6)
    # IDF1: A is best mapped to hypothesis 2 (4 frames within 0.75 m; hypothesis 1 only 2):
    # IDTP = 4, IDFN = 7 - 4 = 3, IDFP = 9 hypothesis detections - 4 = 5
    assert s["idf1"] == pytest.approx(2 * 4 / (2 * 4 + 5 + 3))
    assert events.loc[events["type"] == "SWITCH", "k"].tolist() == [4]
    assert sorted(events.loc[events["type"] == "FP", "k"]) == [2, 3, 5]
    assert events.loc[events["type"] == "MISS", "k"].tolist() == [2]


def test_clear_mot_frames_without_anything_count_nothing():
    gt, hyp = _sequence()
    s8, _ = clear_mot(gt, hyp, n_frames=8)
    s20, _ = clear_mot(gt, hyp, n_frames=20)    # 12 empty scans at the end
    assert s20["n_frames"] == 20 and s20["mota"] == s8["mota"]


def test_clear_mot_refuses_frames_outside_the_recording():
    gt, hyp = _sequence()
    with pytest.raises(Exception, match="outside 0..6"):
        clear_mot(gt, hyp, n_frames=7)


def test_person_hypothesis_is_the_leg_midpoint_and_restarts_start_new_ids():
    x = np.array([[np.nan, 1.0, 1.0, 2.0], [np.nan, 1.2, np.nan, 2.4]])
    y = np.array([[np.nan, 0.0, 0.0, 1.0], [np.nan, 0.2, np.nan, 1.0]])
    h = person_hypotheses(x, y, restarts=[3])
    assert h["k"].tolist() == [1, 3]                 # scan 2 has one leg only: no person
    assert h["hyp_id"].tolist() == [1, 2]
    assert h["x_m"].tolist() == pytest.approx([1.1, 2.2])
    assert h["y_m"].tolist() == pytest.approx([0.1, 1.0])


def test_false_leg_tracks_count_runs_off_the_annotated_person():
    t = np.arange(20) * 0.1
    gt = pd.DataFrame({"k": np.arange(20), "x_m": 1.0, "y_m": 0.0})
    x = np.full((2, 20), 1.1)
    y = np.zeros((2, 20))
    x[0, 5:12] = 4.0            # left leg on a wall for 7 scans (0.7 s): one false track
    x[1, 15:17] = 4.0           # right leg off for 2 scans (0.2 s): shorter than 0.5 s
    r = false_leg_tracks(x, y, t, gt, match_m=0.75, min_false_s=0.5)
    assert r["false_leg_tracks"] == 1
    assert r["false_leg_time_s"] == pytest.approx(0.7)
    assert r["recording_min"] == pytest.approx(2.0 / 60)
    assert r["false_leg_tracks_per_min"] == pytest.approx(30.0)
    gt_gap = gt[gt["k"] < 10]   # nobody annotated after scan 9: both legs false there;
    # the left leg's wall run (5-11) runs on into the gap: one run per leg
    r = false_leg_tracks(x, y, t, gt_gap)
    assert r["false_leg_tracks"] == 2 and r["false_leg_time_s"] == pytest.approx(1.5 + 1.0)


# -- position CSV ----------------------------------------------------------------------------
def test_position_csv_round_trip_and_scan_assignment(tmp_path):
    pos = pd.DataFrame({"t_s": [10.02, 10.11, 10.5], "x_m": [1.0, 1.1, 1.2],
                        "y_m": [0.0, 0.1, 0.2], "id": ["p1", "p1", "p1"],
                        "frame": "laser"})
    p = write_position_csv(tmp_path / "ann.positions.csv", pos)
    back = read_position_csv(p)
    assert back["k"].tolist() == [-1, -1, -1]
    scan_t = np.arange(10.0, 10.35, 0.1)              # scans at 10.0 .. 10.3
    a = assign_scans(back, scan_t)
    assert a["k"].tolist() == [0, 1]                  # 10.5 is no scan's: dropped
    (tmp_path / "bad.csv").write_text("t_s,x_m\n1,2\n")
    with pytest.raises(FileFormatError, match="first line"):
        read_position_csv(tmp_path / "bad.csv")


# -- the annotation initialiser ------------------------------------------------------------
def _two_people():
    # scan 0: a chair-leg pair close to the laser and the subject's legs 2 m away
    scan = np.array([[0.8, -0.2], [0.8, 0.1], [2.0, 0.5], [2.0, 0.8]])
    return DetectionSeries([scan, scan], [["SL"] * 4] * 2)


def test_annotated_pair_starts_on_the_annotated_person_not_the_closest_pair():
    src = _two_people()
    closest = INITIALISERS.build({"name": "closest_pair", "require_motion": False})
    assert sorted(closest.find(src, 0.1)[1:]) == [0, 1]          # the chair
    ann = INITIALISERS.build({"name": "annotated_pair", "k": 0, "x_m": 2.05, "y_m": 0.6})
    k, il, ir = ann.find(src, 0.1)
    assert k == 0 and (il, ir) == (3, 2)                        # left = larger bearing
    far = INITIALISERS.build({"name": "annotated_pair", "k": 0, "x_m": 4.0, "y_m": 0.0})
    assert far.find(src, 0.1) is None                           # nobody within 0.75 m
    with pytest.raises(ConfigError, match="annotated scan"):
        INITIALISERS.build({"name": "annotated_pair"})


# -- the steps on the real bag -----------------------------------------------------------------
@pytest.mark.realdata
@pytest.mark.slow
def test_track_and_evaluate_the_outdoor_bag_from_its_first_annotation(outdoor, tmp_path):
    from gaitval.pipeline.legbench import legbench_evaluate_step, legbench_track_step
    path, (ann, _) = outdoor
    topics = {"annotation_topic": "/ground_truth_people_tracks", "scan_topic": "/scan_base2"}
    legbench_track_step(path, "tug_m1", tmp_path / "track.parquet", init="annotation",
                        annotations=path, **topics)
    s = legbench_evaluate_step(tmp_path / "track.parquet", path, tmp_path / "a",
                               **topics).iloc[0]
    assert (s["n_scans"], s["gt"], s["annotated_scans"]) == (7170, 6179, 6179)
    # the track starts on the first annotated scan, on the annotated person
    assert s["k_init"] == int(ann["k"].min()) and s["init_offset_m"] < 0.75
    assert s["mota"] == pytest.approx(1 - (s["fn"] + s["fp"] + s["idsw"]) / s["gt"])
    frames = pd.read_parquet(tmp_path / "a" / "frames.parquet")
    assert (frames["event"] == "MISS").sum() == s["fn"]
    # same inputs, same bytes
    legbench_evaluate_step(tmp_path / "track.parquet", path, tmp_path / "b", **topics)
    for f in ("summary.parquet", "frames.parquet"):
        assert (tmp_path / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes()


# -- issue 36: scoring like the benchmark's authors --------------------------------------------
def test_reference_id_switches_also_count_a_hypothesis_that_moves_to_another_person():
    from gaitval.evaluate.clearmot import following_counts, reference_id_switches
    # two people A (x = 0) and B (x = 3); hypothesis 1 follows A, then jumps to B while
    # hypothesis 2 picks A up: A changes hypothesis (both counts), and hypothesis 1 changes
    # person (the reference script's count only); frame 3 has nobody annotated
    gt = pd.DataFrame([(0, "A", 0.0, 0.0), (0, "B", 3.0, 0.0), (1, "A", 0.0, 0.0),
                       (1, "B", 3.0, 0.0), (2, "A", 0.0, 0.0), (2, "B", 3.0, 0.0)],
                      columns=["k", "id", "x_m", "y_m"])
    hyp = pd.DataFrame([(0, 1, 0.1, 0.0), (1, 1, 0.1, 0.0), (2, 1, 3.1, 0.0),
                        (2, 2, 0.1, 0.0), (3, 9, 5.0, 5.0)],
                       columns=["k", "hyp_id", "x_m", "y_m"])
    s, events = clear_mot(gt, hyp, n_frames=4)
    # A: hyp 1, 1, then 2 (a switch); B: missed twice, then matched to hyp 1 for the first
    # time (motmetrics: no switch for B; the reference script: hyp 1 was A's, a switch)
    assert s["idsw"] == 1
    assert reference_id_switches(events) == 2
    f = following_counts(s, events)
    # 4 matched pairs, 2 of them switches by the reference rule: "valid" = 2, and
    # valid + IDSW + misses = the 6 annotations, as in the benchmark's Table III
    assert (f["pairs"], f["matched"], f["misses"], f["idsw"], f["idsw_ref"]) == \
        (4, 2, 2, 1, 2)
    # following: the false positive of frame 3 is ignored
    assert f["mota_following"] == pytest.approx(1 - (2 + 1) / 6)
    assert s["fp"] == 1 and s["mota"] == pytest.approx(1 - (2 + 1 + 1) / 6)


def test_sector_keeps_bearings_inside_its_bounds():
    from gaitval.evaluate.clearmot import in_sector
    x = np.array([1.0, 1.0, 1.0, -1.0])
    y = np.array([0.0, 1.0, -1.0, 0.0])          # 0°, 45°, -45°, 180°
    assert in_sector(x, y, (-80, 12)).tolist() == [True, False, True, False]
    assert in_sector(x, y, None).all()


def test_annotation_initialiser_follows_the_annotation_while_it_searches():
    # the person walks away from the first click: scans 0-2 show one leg only, scan 3 the
    # pair at x = 2.0, 0.9 m from the first click but beside the click of scan 3
    far = np.array([[2.0, 0.25], [2.0, -0.05]])
    src = DetectionSeries([np.array([[1.1, 0.1]])] * 3 + [far], [["SL"]] * 3 + [["SL"] * 2])
    held = INITIALISERS.build({"name": "annotated_pair", "k": 0, "x_m": 1.1, "y_m": 0.1})
    assert held.find(src, 0.1) is None                    # the first click held: too far
    follows = INITIALISERS.build({"name": "annotated_pair", "k": 0, "x_m": 1.1, "y_m": 0.1,
                                  "path": [[1, 1.4, 0.1], [3, 2.0, 0.1]]})
    assert follows.find(src, 0.1) == (3, 0, 1)


def test_benchmark_table_sets_published_rows_beside_gaitvals():
    from gaitval.tables.legbench import benchmark_table
    row = {"trial": "t", "method": "tug_m1", "init": "annotation", "mota": 0.5,
           "motp_m": 0.1, "idsw": 1, "idsw_ref": 2, "idf1": 0.6, "gt": 100, "fn": 9,
           "fp": 40, "matches": 90, "matched_ref": 89, "mota_following": 0.9,
           "sector_deg": "",
           "false_leg_tracks": 0, "false_leg_tracks_per_min": 0.0, "false_leg_time_s": 0.0,
           "tracked_fraction": 1.0, "k_init": 0, "t_init_s": 0.0, "init_offset_m": 0.1,
           "annotations_in_window": np.nan, "benchmark_set": "following_outdoor"}
    b = benchmark_table(pd.DataFrame([row, {**row, "trial": "u", "matches": 80,
                                            "matched_ref": 79, "fn": 19, "motp_m": 0.2}]))
    assert b["source"].tolist()[:3] == ["Leigh et al. ICRA 2015, Table III"] * 3
    joint = b.iloc[2]
    assert (joint["tracker"], joint["matched"], joint["idsw_ref"], joint["misses"]) == \
        ("leg_tracker Joint Leg", 6073, 21, 104)
    assert joint["matched_pct"] == pytest.approx(100 * 6073 / (6073 + 21 + 104))
    ours = b.iloc[3]
    assert (ours["matched"], ours["misses"], ours["idsw"], ours["idsw_ref"]) == (168, 28, 2, 4)
    assert ours["fp"] == ""                                   # following: FPs ignored
    # MOTA from the reference script's ID switches (as the published rows), motmetrics' beside
    assert ours["mota_pct"] == pytest.approx(100 * (1 - (28 + 4) / 200))
    assert ours["mota_pct_motmetrics"] == pytest.approx(100 * (1 - (28 + 2) / 200))
    assert ours["motp_m"] == pytest.approx((91 * 0.1 + 81 * 0.2) / 172)   # over all pairs
    assert benchmark_table(pd.DataFrame([{**row, "benchmark_set": ""}])).empty
