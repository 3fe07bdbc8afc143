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
from gaitval.io.tracks import read_bag_leg_detections, read_bag_tracks
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
