"""Issue 37: leg_tracker's leg detections (leg_tracker/LegArray, /detected_leg_clusters: no
identity, no side) read from a ROS 1 bag and scored as detections against the mocap legs
(gaitval/evaluate/leg_detections.py), never as tracks."""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.evaluate.leg_detections import detection_statistics
from gaitval.io.tracks.bag import read_bag_leg_detections, read_bag_tracks
from test_io_tracks_bag import DEFS

#: per scan (t = 100 s + k 25 ms) the detections; the legs stand at L (1, 0.1), R (1, -0.1)
SCANS = [[(1.01, 0.1), (1.0, -0.12)],           # both legs, 1 and 2 cm off
         [(1.0, 0.1)],                          # R missed
         [(1.0, 0.1), (1.0, -0.1), (3.0, 0.0)],  # both, and a false detection
         []]                                    # none


def detection_bag(path: Path, frame: str = "laser") -> Path:
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = {}
    for name in ("leg_tracker/msg/Leg", "leg_tracker/msg/LegArray"):
        types.update(get_types_from_msg(DEFS[name], name))
    store.register(types)
    T = store.types
    with Writer(path) as w:
        cs = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=store)
        cl = w.add_connection("/detected_leg_clusters", "leg_tracker/msg/LegArray",
                              typestore=store)
        for k, dets in enumerate(SCANS):
            hdr = T["std_msgs/msg/Header"](seq=k, stamp=T["builtin_interfaces/msg/Time"](
                sec=100, nanosec=25_000_000 * k), frame_id="laser")
            scan = T["sensor_msgs/msg/LaserScan"](
                header=hdr, angle_min=-1.0, angle_max=1.0, angle_increment=1.0,
                time_increment=0.0, scan_time=0.025, range_min=0.1, range_max=30.0,
                ranges=np.array([1.0, 2.0, 3.0], np.float32),
                intensities=np.array([], np.float32))
            w.write(cs, 10**9 + k * 10**7, store.serialize_ros1(scan,
                                                                "sensor_msgs/msg/LaserScan"))
            dhdr = T["std_msgs/msg/Header"](seq=k, stamp=hdr.stamp, frame_id=frame)
            legs = [T["leg_tracker/msg/Leg"](position=T["geometry_msgs/msg/Point"](
                x=x, y=y, z=0.0), confidence=0.8) for x, y in dets]
            w.write(cl, 10**9 + k * 10**7 + 1, store.serialize_ros1(
                T["leg_tracker/msg/LegArray"](header=dhdr, legs=legs),
                "leg_tracker/msg/LegArray"))
    return path


def truth() -> pd.DataFrame:
    t = np.repeat(100.0 + 0.025 * np.arange(len(SCANS)), 2)
    return pd.DataFrame({"t_sensor_s": t, "side": ["L", "R"] * len(SCANS),
                         "xs_m": 1.0, "ys_m": [0.1, -0.1] * len(SCANS), "valid": True})


def test_leg_array_reads_and_scores_as_detections(tmp_path):
    bag = detection_bag(tmp_path / "d.bag")
    det, meta = read_bag_leg_detections(bag)
    assert meta["source"] == "leg_tracker/msg/LegArray on /detected_leg_clusters"
    assert meta["n_messages"] == 4 and len(det) == 6
    assert det["msg"].tolist() == [1, 1, 2, 3, 3, 3]
    per_scan, s = detection_statistics(det, meta["t_messages"], truth())
    assert s["n_scans"] == 4
    assert s["detection_rate_L"] == pytest.approx(3 / 4)
    assert s["detection_rate_R"] == pytest.approx(2 / 4)
    # matched errors: L 0.01, 0, 0 in x; R -0.02 in y (scan 0)
    assert s["rmse_x_m"] == pytest.approx(math.sqrt(0.01 ** 2 / 5))
    assert s["rmse_y_m"] == pytest.approx(math.sqrt(0.02 ** 2 / 5))
    assert s["false_per_scan"] == pytest.approx(1 / 4)
    assert per_scan["detected"].tolist() == [True, True, True, False, True, True, False,
                                             False]
    # a gate of 1.5 cm: R's 2 cm detection of scan 0 is no longer R's, but a false one
    _, s2 = detection_statistics(det, meta["t_messages"], truth(), gate_m=0.015)
    assert s2["detection_rate_R"] == pytest.approx(1 / 4)
    assert s2["false_per_scan"] == pytest.approx(2 / 4)


def test_leg_detections_verb_writes_summary_and_per_scan(tmp_path):
    from gaitval.cli import main

    bag = detection_bag(tmp_path / "d.bag")
    gt = tmp_path / "groundtruth.parquet"
    truth().to_parquet(gt)
    out = tmp_path / "det"
    assert main(["leg-detections", "--detections", str(bag), "--groundtruth", str(gt),
                 "--trial", "T1", "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["trial"] == "T1" and s["detection_rate_L"] == pytest.approx(0.75)
    assert len(pd.read_parquet(out / "per_scan.parquet")) == 8
    late = truth().assign(t_sensor_s=lambda d: d["t_sensor_s"] + 5.0)
    late.to_parquet(gt)
    assert main(["leg-detections", "--detections", str(bag), "--groundtruth", str(gt),
                 "--trial", "T1", "--out", str(out)]) == 1


def test_leg_array_is_no_track_and_other_frames_are_refused(tmp_path):
    bag = detection_bag(tmp_path / "d.bag")
    with pytest.raises(FileFormatError) as exc:
        read_bag_tracks(bag, "/detected_leg_clusters", trial="T1")
    msg = str(exc.value)
    for w in (str(bag), "trial T1", "without identity or side, not tracks",
              "gaitval leg-detections"):
        assert w in msg, (w, msg)
    with pytest.raises(FileFormatError, match="holds sensor_msgs/msg/LaserScan, not "
                                              "leg_tracker/msg/LegArray"):
        read_bag_leg_detections(bag, "/scan")
    with pytest.raises(FileFormatError, match="topic '/legs' is not in this bag"):
        read_bag_leg_detections(bag, "/legs")
    odom = detection_bag(tmp_path / "o.bag", frame="odom")
    with pytest.raises(FileFormatError, match=r"frame\(s\) \['odom'\]"):
        read_bag_leg_detections(odom)


# -- the detections file (*.detections.csv / .parquet) and the detection table -----------
def detections_csv(path: Path, body: str, units: str = "m", frame: str = "sensor",
                   clock: str = "sensor") -> Path:
    path.write_text(f"# gaitval-detections v1\n# units: {units}\n# frame: {frame}\n"
                    f"# clock: {clock}\n{body}")
    return path


#: SCANS as a file: t = 100 s + k 25 ms; the empty scan one row without x, y
CSV_BODY = ("t_s,x,y\n100.0,1.01,0.1\n100.0,1.0,-0.12\n100.025,1.0,0.1\n"
            "100.05,1.0,0.1\n100.05,1.0,-0.1\n100.05,3.0,0.0\n100.075,,\n")


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_detections_file_scores_as_the_bag_does(tmp_path, suffix):
    from gaitval.io.tracks.detections import read_detections, write_detections

    f = detections_csv(tmp_path / "d.detections.csv", CSV_BODY)
    if suffix == ".parquet":
        rows, _ = read_detections(f)
        f = write_detections(pd.DataFrame({"t_s": [100.0, 100.0, 100.025, 100.05, 100.05,
                                                   100.05, 100.075],
                                           "x": [1.01, 1.0, 1.0, 1.0, 1.0, 3.0, np.nan],
                                           "y": [0.1, -0.12, 0.1, 0.1, -0.1, 0.0, np.nan]}),
                             tmp_path / "d.detections.parquet")
    det, meta = read_detections(f)
    assert meta["n_messages"] == 4 and len(det) == 6
    _, from_file = detection_statistics(det, meta["t_messages"], truth())
    bag = detection_bag(tmp_path / "d.bag")
    det_b, meta_b = read_bag_leg_detections(bag)
    _, from_bag = detection_statistics(det_b, meta_b["t_messages"], truth())
    assert from_file == pytest.approx(from_bag)


@pytest.mark.parametrize("head, body, words", [
    ({"units": "cm"}, CSV_BODY, ["'units' is 'cm'", "(line 2)"]),
    ({}, "t_s,side,x,y\n100.0,L,1.0,0.1\n", ["unknown column(s) 'side'", "track file"]),
    ({}, "t_s,x,y\n100.0,1.0,\n", ["line 6", "one of 'x', 'y' is empty"]),
    ({}, "t_s,x,y\n100.0,1.0,abc\n", ["column 'y', line 6", "'abc' is not a number"]),
    ({}, "t_s,x\n100.0,1.0\n", ["column 'y' is missing"]),
])
def test_a_bad_detections_file_names_the_file_field_and_line(tmp_path, head, body, words):
    from gaitval.io.tracks.detections import read_detections

    f = detections_csv(tmp_path / "d.detections.csv", body, **head)
    with pytest.raises(FileFormatError) as exc:
        read_detections(f, trial="T1")
    msg = str(exc.value)
    for w in [str(f), "trial T1"] + words:
        assert w in msg, (w, msg)


def test_detections_in_mm_or_outside_the_recording_are_refused(tmp_path):
    from gaitval.io.tracks.detections import read_detections
    from gaitval.io.tracks.sensor import detections_to_sensor

    scan_t = 100.0 + 0.025 * np.arange(4)
    det, meta = read_detections(detections_csv(tmp_path / "a.detections.csv",
                                               CSV_BODY.replace("1.0,", "1000.0,")))
    with pytest.raises(FileFormatError, match=r"line 7: detection \(1000, -0.12\) m .* beyond "
                                              r"its range \(30 m\).*units 'm'"):
        detections_to_sensor(det, meta, scan_t=scan_t, max_range_m=30.0)
    det, meta = read_detections(detections_csv(tmp_path / "b.detections.csv", CSV_BODY))
    with pytest.raises(FileFormatError, match="outside the recording"):
        detections_to_sensor(det, meta, scan_t=scan_t + 10.0, tolerance_s=0.025)
    det, meta = read_detections(detections_csv(tmp_path / "c.detections.csv", CSV_BODY,
                                               clock="mocap"))
    with pytest.raises(FileFormatError, match="needs the trial's registration"):
        detections_to_sensor(det, meta, {"status": "refused"})
    conv, tm = detections_to_sensor(det, meta, {"clock_offset_s": -50.0}, scan_t=scan_t - 50.0)
    assert tm == pytest.approx(list(scan_t - 50.0)) and len(conv) == 6


def test_the_detection_table_and_its_report_section(tmp_path):
    from gaitval.cli import main
    from gaitval.report.index import collect
    from gaitval.tables.detections import detections_table

    gt = tmp_path / "groundtruth.parquet"
    truth().to_parquet(gt)
    f = detections_csv(tmp_path / "d.detections.csv", CSV_BODY)
    dirs = []
    for t in ("T1", "T2"):
        out = tmp_path / "det" / t
        assert main(["leg-detections", "--detections", str(f), "--groundtruth", str(gt),
                     "--trial", t, "--method", "mine", "--protocol", "tug",
                     "--out", str(out)]) == 0
        dirs.append(str(out))
    reg = tmp_path / "registration.json"
    reg.write_text(json.dumps({"status": "refused"}))
    out = tmp_path / "det" / "T3"
    assert main(["leg-detections", "--detections", str(f), "--groundtruth", str(gt),
                 "--registration", str(reg), "--trial", "T3", "--method", "mine",
                 "--protocol", "tug", "--out", str(out)]) == 0
    tab = detections_table(dirs + [str(out)])
    row = tab.iloc[0]
    assert (row["method"], row["n_trials"], row["n_not_registered"], row["n_scans"]) == (
        "mine", 3, 1, 8)
    assert row["left_detection_rate"] == pytest.approx(0.75)
    assert row["detection_rate"] == pytest.approx(5 / 8)
    assert row["false_per_scan"] == pytest.approx(0.25)
    rd = tmp_path / "reports"
    assert main(["leg-detections-table", *dirs, str(out), "--out-stem",
                 str(rd / "tables" / "detections_table"), "--reports-dir", str(rd)]) == 0
    sec = {s["key"]: s for s in collect(rd)["sections"]}
    item = sec["detections"]["items"][0]
    assert item["stem"] == "detections_table" and "no row in the tracking tables" in \
        " ".join(item["notes"])
    assert "Left detection (%)" in [h for h, _ in item["header"]]   # its label, with its unit


def test_rollator_detections_in_the_mocap_frame_are_refused_and_a_third_clock_is_offset(
        tmp_path):
    """On a rollator trial the laser moves: detections in the mocap frame are refused with
    one error naming the file and the header field; detections stamped on a third clock
    score like the sensor-clock file once the header gives the offset."""
    from gaitval.pipeline.steps.external import leg_detections_step

    gt = tmp_path / "groundtruth.parquet"
    truth().to_parquet(gt)
    reg = tmp_path / "registration.json"
    reg.write_text(json.dumps({"status": "ok", "clock_offset_s": 0.0, "x_m": None,
                               "y_m": None, "yaw_rad": None}))
    f = detections_csv(tmp_path / "m.detections.csv", CSV_BODY, frame="mocap")
    with pytest.raises(FileFormatError) as exc:
        leg_detections_step(f, gt, tmp_path / "o", trial="rollator_P1", moving_sensor=True,
                            registration_json=reg)
    msg = str(exc.value)
    assert "'frame' is 'mocap'" in msg and "laser moves" in msg and str(f) in msg
    plain = leg_detections_step(detections_csv(tmp_path / "s.detections.csv", CSV_BODY),
                                gt, tmp_path / "o1", trial="rollator_P1", moving_sensor=True)
    third = tmp_path / "t.detections.csv"             # a clock that started 100 s later
    third.write_text("# gaitval-detections v1\n# units: m\n# frame: sensor\n"
                     "# clock: sensor\n# clock_offset_s: 100.0\n"
                     + CSV_BODY.replace("100.", "0."))
    got = leg_detections_step(third, gt, tmp_path / "o2", trial="rollator_P1",
                              moving_sensor=True)
    for k in ("n_scans", "detection_rate_L", "detection_rate_R", "false_per_scan"):
        assert got[k] == plain[k], k
