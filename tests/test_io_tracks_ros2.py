"""Issue 37: the trackers' topics of a ROS 2 bag (a folder, rosbag2 metadata version 9,
message definitions in its metadata; rosbags reads both ROS 1 and ROS 2): leg_tracker's
PersonArray (/people_tracked, each leg a person), people_msgs/People and LegArray
(/detected_leg_clusters) read as from a ROS 1 bag -- nothing needs ROS installed."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from gaitval.errors import FileFormatError
from gaitval.evaluate.leg_detections import detection_statistics
from gaitval.io.tracks.bag import people_to_legs, read_bag_leg_detections, read_bag_tracks
from test_io_tracks_bag import DEFS
from test_leg_detections import SCANS, truth

#: ROS 2 spells the header's type with its package
ROS2_DEFS = {k: v.replace("Header header", "std_msgs/Header header") for k, v in DEFS.items()}


def ros2_bag(path: Path, legs_frame: str = "laser") -> Path:
    """/scan, /people_tracked (legs L (1, 0.1), R (1, -0.1) as persons 1 and 2), /people
    (the same as people_msgs/People, names "l", "r") and /detected_leg_clusters (SCANS),
    one message each per scan t = 100 s + k 25 ms."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    types = {}
    for name, text in ROS2_DEFS.items():
        types.update(get_types_from_msg(text, name))
    ts.register(types)
    T = ts.types
    P = T["geometry_msgs/msg/Point"]
    shutil.rmtree(path, ignore_errors=True)
    with Writer(path, version=9) as w:
        cs = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=ts)
        cp = w.add_connection("/people_tracked", "leg_tracker/msg/PersonArray", typestore=ts)
        cq = w.add_connection("/people", "people_msgs/msg/People", typestore=ts)
        cl = w.add_connection("/detected_leg_clusters", "leg_tracker/msg/LegArray",
                              typestore=ts)
        for k, dets in enumerate(SCANS):
            stamp = T["builtin_interfaces/msg/Time"](sec=100, nanosec=25_000_000 * k)
            h = T["std_msgs/msg/Header"](stamp=stamp, frame_id="laser")
            t_ns = 10**9 + k * 10**7
            scan = T["sensor_msgs/msg/LaserScan"](
                header=h, angle_min=-1.0, angle_max=1.0, angle_increment=1.0,
                time_increment=0.0, scan_time=0.025, range_min=0.1, range_max=30.0,
                ranges=np.array([1.0, 2.0, 3.0], np.float32),
                intensities=np.array([], np.float32))
            w.write(cs, t_ns, ts.serialize_cdr(scan, "sensor_msgs/msg/LaserScan"))

            def pose(y):
                return T["geometry_msgs/msg/Pose"](
                    position=P(x=1.0, y=y, z=0.0),
                    orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0))
            people = [T["leg_tracker/msg/Person"](pose=pose(0.1), id=1),
                      T["leg_tracker/msg/Person"](pose=pose(-0.1), id=2)]
            w.write(cp, t_ns + 1, ts.serialize_cdr(
                T["leg_tracker/msg/PersonArray"](header=h, people=people),
                "leg_tracker/msg/PersonArray"))
            ppl = [T["people_msgs/msg/Person"](name=n, position=P(x=1.0, y=y, z=0.0),
                                                velocity=P(x=0.0, y=0.0, z=0.0),
                                                reliability=1.0, tagnames=[], tags=[])
                   for n, y in (("l", 0.1), ("r", -0.1))]
            w.write(cq, t_ns + 2, ts.serialize_cdr(T["people_msgs/msg/People"](
                header=h, people=ppl), "people_msgs/msg/People"))
            hl = T["std_msgs/msg/Header"](stamp=stamp, frame_id=legs_frame)
            legs = [T["leg_tracker/msg/Leg"](position=P(x=x, y=y, z=0.0), confidence=0.8)
                    for x, y in dets]
            w.write(cl, t_ns + 3, ts.serialize_cdr(T["leg_tracker/msg/LegArray"](
                header=hl, legs=legs), "leg_tracker/msg/LegArray"))
    return path


@pytest.mark.parametrize("topic, legs", [("/people_tracked", {"L": "1", "R": "2"}),
                                         ("/people", {"L": "l", "R": "r"})])
def test_a_ros2_bags_people_are_legs_as_from_ros1(tmp_path, topic, legs):
    bag = ros2_bag(tmp_path / "b2")
    rows, meta = read_bag_tracks(bag, topic, trial="T1")
    assert meta["source"].endswith(f"on {topic}") and meta["frame"] == "sensor"
    assert len(rows) == 2 * len(SCANS)
    got = people_to_legs(rows, legs, path=bag, trial="T1", topic=meta["source"])
    want = pd.DataFrame({"t_s": np.repeat(100.0 + 0.025 * np.arange(len(SCANS)), 2),
                         "side": ["L", "R"] * len(SCANS),
                         "x_m": 1.0, "y_m": [0.1, -0.1] * len(SCANS)})
    got = got.sort_values(["t_s", "side"]).reset_index(drop=True)
    np.testing.assert_allclose(got["t_s"], want["t_s"], atol=1e-9)
    assert got["side"].tolist() == want["side"].tolist()
    np.testing.assert_allclose(got[["x_m", "y_m"]], want[["x_m", "y_m"]])


def test_a_ros2_bags_leg_detections_score_as_from_ros1(tmp_path):
    from test_leg_detections import detection_bag

    det, meta = read_bag_leg_detections(ros2_bag(tmp_path / "b2"))
    assert meta["n_messages"] == len(SCANS) and len(det) == 6
    _, s2 = detection_statistics(det, meta["t_messages"], truth())
    d1, m1 = read_bag_leg_detections(detection_bag(tmp_path / "b1.bag"))
    _, s1 = detection_statistics(d1, m1["t_messages"], truth())
    assert s2 == pytest.approx(s1)
    with pytest.raises(FileFormatError, match=r"frame\(s\) \['odom'\]"):
        read_bag_leg_detections(ros2_bag(tmp_path / "o2", legs_frame="odom"))
