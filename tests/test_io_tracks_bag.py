"""Issue 37: a tracker's people topics of a ROS 1 bag (leg_tracker/PersonArray,
people_msgs/People) into the leg-track exchange format, definitions taken from the bag;
leg_tracker/LegArray and unknown topics refused with one clear error."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.tracks.bag import read_bag_tracks
from gaitval.io.tracks.read import read_tracks
from gaitval.io.tracks.write import write_tracks

DEFS = {
    "leg_tracker/msg/Person": "geometry_msgs/Pose pose\nuint32 id\n",
    "leg_tracker/msg/PersonArray": "Header header\nleg_tracker/Person[] people\n",
    "leg_tracker/msg/Leg": "geometry_msgs/Point position\nfloat32 confidence\n",
    "leg_tracker/msg/LegArray": "Header header\nleg_tracker/Leg[] legs\n",
    "people_msgs/msg/Person": ("string name\ngeometry_msgs/Point position\n"
                               "geometry_msgs/Point velocity\nfloat64 reliability\n"
                               "string[] tagnames\nstring[] tags\n"),
    "people_msgs/msg/People": "Header header\npeople_msgs/Person[] people\n",
}


def make_bag(path: Path, frame: str = "laser", people_frame: str = "laser") -> Path:
    """/scan (3 scans) and the tracker's /people_tracked, /people, /detected_leg_clusters."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    types = {}
    for name, text in DEFS.items():
        types.update(get_types_from_msg(text, name))
    store.register(types)
    T = store.types
    Time = T["builtin_interfaces/msg/Time"]

    def header(k, fr):
        return T["std_msgs/msg/Header"](seq=k, stamp=Time(sec=100, nanosec=25_000_000 * k),
                                        frame_id=fr)

    def point(x, y):
        return T["geometry_msgs/msg/Point"](x=x, y=y, z=0.0)

    with Writer(path) as w:
        cs = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=store)
        cp = w.add_connection("/people_tracked", "leg_tracker/msg/PersonArray",
                              typestore=store)
        cq = w.add_connection("/people", "people_msgs/msg/People", typestore=store)
        cl = w.add_connection("/detected_leg_clusters", "leg_tracker/msg/LegArray",
                              typestore=store)
        for k in range(3):
            ts = 1_000_000_000 + k * 25_000_000
            scan = T["sensor_msgs/msg/LaserScan"](
                header=header(k, frame), angle_min=-1.0, angle_max=1.0, angle_increment=1.0,
                time_increment=0.0, scan_time=0.025, range_min=0.1, range_max=30.0,
                ranges=np.array([1.0, 2.0, 3.0], np.float32),
                intensities=np.array([], np.float32))
            w.write(cs, ts, store.serialize_ros1(scan, "sensor_msgs/msg/LaserScan"))
            pose = T["geometry_msgs/msg/Pose"](
                position=point(1.0 + 0.1 * k, 0.5),
                orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0))
            people = [T["leg_tracker/msg/Person"](pose=pose, id=7)]
            if k:
                people.append(T["leg_tracker/msg/Person"](pose=pose, id=9))
            w.write(cp, ts + 1, store.serialize_ros1(T["leg_tracker/msg/PersonArray"](
                header=header(k, people_frame), people=people), "leg_tracker/msg/PersonArray"))
            pm = T["people_msgs/msg/Person"](name="anna", position=point(2.0, -0.2 * k),
                                             velocity=point(0.0, 0.0), reliability=1.0,
                                             tagnames=[], tags=[])
            w.write(cq, ts + 2, store.serialize_ros1(T["people_msgs/msg/People"](
                header=header(k, frame), people=[pm]), "people_msgs/msg/People"))
            leg = T["leg_tracker/msg/Leg"](position=point(1.0, 0.4), confidence=0.9)
            w.write(cl, ts + 3, store.serialize_ros1(T["leg_tracker/msg/LegArray"](
                header=header(k, frame), legs=[leg]), "leg_tracker/msg/LegArray"))
    return path


def test_person_array_and_people_topics_read_and_round_trip(tmp_path):
    bag = make_bag(tmp_path / "t.bag")
    rows, meta = read_bag_tracks(bag, "/people_tracked")
    assert (meta["units"], meta["frame"], meta["clock"]) == ("m", "sensor", "sensor")
    assert rows["person"].tolist() == ["7", "7", "9", "7", "9"]
    np.testing.assert_allclose(rows["t_s"], [100.0, 100.025, 100.025, 100.05, 100.05])
    np.testing.assert_allclose(rows["x"], [1.0, 1.1, 1.1, 1.2, 1.2])
    out = write_tracks(rows, tmp_path / "p.tracks.csv", source=meta["source"])
    back, m2 = read_tracks(out)
    assert back["person"].tolist() == rows["person"].tolist()
    np.testing.assert_array_equal(back["x_m"], rows["x"])
    rows, meta = read_bag_tracks(bag, "people")
    assert rows["person"].tolist() == ["anna"] * 3
    np.testing.assert_allclose(rows["y"], [0.0, -0.2, -0.4])


@pytest.mark.parametrize("topic, words", [
    ("/nope", ["topic '/nope' is not in this bag", "/people_tracked"]),
    ("/detected_leg_clusters", ["LegArray", "without identity or side"]),
    (None, ["several tracker topic(s)"]),
    ("/scan", ["holds sensor_msgs/msg/LaserScan"]),
])
def test_bad_topics_are_one_clear_error(tmp_path, topic, words):
    bag = make_bag(tmp_path / "t.bag")
    with pytest.raises(FileFormatError) as exc:
        read_bag_tracks(bag, topic, trial="T9")
    msg = str(exc.value)
    assert str(bag) in msg and "trial T9" in msg
    for w in words:
        assert w in msg, (w, msg)


def test_tracks_in_another_frame_are_refused(tmp_path):
    bag = make_bag(tmp_path / "t.bag", people_frame="odom")
    with pytest.raises(FileFormatError, match=r"frame\(s\) \['odom'\] but the scans in "
                                              r"\['laser'\]"):
        read_bag_tracks(bag, "/people_tracked")


def test_export_tracks_verb_converts_a_bag_topic(tmp_path):
    from gaitval.cli import main

    bag = make_bag(tmp_path / "t.bag")
    out = tmp_path / "people.tracks.parquet"
    assert main(["export-tracks", str(bag), str(out), "--topic", "/people", "--units",
                 "mm"]) == 0
    rows, meta = read_tracks(out)
    assert meta["units"] == "mm" and meta["source"] == "people_msgs/msg/People on /people"
    np.testing.assert_allclose(rows["x_m"], [2.0] * 3)     # read back in metres
    assert main(["export-tracks", str(bag), str(out), "--topic", "/nope"]) == 1


def test_people_as_legs_and_a_missing_leg(tmp_path):
    """A tracker that publishes each leg as a person: ``legs`` names the ids; a time stamp
    without one of them has that leg without a position; an id that never appears is an
    error naming the leg, the id and the ids present."""
    from gaitval.cli import main
    from gaitval.io.tracks.bag import people_to_legs

    bag = make_bag(tmp_path / "t.bag")
    rows, meta = read_bag_tracks(bag, "/people_tracked")
    legs = people_to_legs(rows, {"L": "7", "R": 9}, path=bag)
    assert legs["side"].tolist() == ["L", "R"] * 3
    assert np.isnan(legs["x_m"].iloc[1]) and np.isfinite(legs["x_m"].iloc[2:]).all()
    with pytest.raises(FileFormatError) as exc:
        people_to_legs(rows, {"L": "7", "R": "3"}, path=bag, trial="T9",
                       topic=meta["source"])
    msg = str(exc.value)
    for w in (str(bag), "trial T9", "/people_tracked", "leg R (person id '3') is missing",
              "['7', '9']"):
        assert w in msg, (w, msg)
    with pytest.raises(FileFormatError, match="both sides L and R"):
        people_to_legs(rows, {"L": "7"}, path=bag)
    out = tmp_path / "legs.tracks.csv"
    assert main(["export-tracks", str(bag), str(out), "--topic", "/people_tracked",
                 "--legs", "L=7,R=9"]) == 0
    back, _ = read_tracks(out)           # a valid leg file: both legs at every time stamp
    assert back["side"].tolist() == ["L", "R"] * 3


def test_pose_array_index_is_the_id(tmp_path):
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    T = store.types
    path = tmp_path / "p.bag"
    with Writer(path) as w:
        cs = w.add_connection("/scan", "sensor_msgs/msg/LaserScan", typestore=store)
        cp = w.add_connection("/legs", "geometry_msgs/msg/PoseArray", typestore=store)
        for k in range(2):
            hdr = T["std_msgs/msg/Header"](seq=k, stamp=T["builtin_interfaces/msg/Time"](
                sec=5, nanosec=k * 50_000_000), frame_id="laser")
            scan = T["sensor_msgs/msg/LaserScan"](
                header=hdr, angle_min=-1.0, angle_max=1.0, angle_increment=1.0,
                time_increment=0.0, scan_time=0.05, range_min=0.1, range_max=30.0,
                ranges=np.array([1.0, 2.0, 3.0], np.float32),
                intensities=np.array([], np.float32))
            w.write(cs, 10**9 + k, store.serialize_ros1(scan, "sensor_msgs/msg/LaserScan"))
            poses = [T["geometry_msgs/msg/Pose"](
                position=T["geometry_msgs/msg/Point"](x=1.0 + k, y=y, z=0.0),
                orientation=T["geometry_msgs/msg/Quaternion"](x=0.0, y=0.0, z=0.0, w=1.0))
                for y in (0.1, -0.1)]
            w.write(cp, 10**9 + k + 1, store.serialize_ros1(T["geometry_msgs/msg/PoseArray"](
                header=hdr, poses=poses), "geometry_msgs/msg/PoseArray"))
    rows, meta = read_bag_tracks(path)
    assert meta["source"] == "geometry_msgs/msg/PoseArray on /legs"
    assert rows["person"].tolist() == ["0", "1", "0", "1"]
    np.testing.assert_allclose(rows["y"], [0.1, -0.1, 0.1, -0.1])
    np.testing.assert_allclose(rows["t_s"], [5.0, 5.0, 5.05, 5.05])


def test_bag_time_stamps_outside_the_recording_name_the_message(tmp_path):
    """A bag's tracks are converted like a file's: a time stamp outside the recording
    names the topic, the message and its field header.stamp."""
    from gaitval.io.tracks.bag import people_to_legs
    from gaitval.io.tracks.sensor import tracks_to_sensor

    bag = make_bag(tmp_path / "t.bag")
    rows, meta = read_bag_tracks(bag, "/people_tracked", trial="T9")
    legs = people_to_legs(rows, {"L": "7", "R": "9"}, path=bag, trial="T9")
    assert legs["msg"].tolist() == [1, 1, 2, 2, 3, 3]
    out = tracks_to_sensor(legs, meta, path=bag, trial="T9", t_range=(100.0, 100.05))
    assert len(out) == 6
    with pytest.raises(FileFormatError) as exc:
        tracks_to_sensor(legs, meta, path=bag, trial="T9", t_range=(100.01, 100.06))
    msg = str(exc.value)
    for w in (str(bag), "trial T9", "leg_tracker/msg/PersonArray on /people_tracked, "
              "message 1, field header.stamp", "time stamp 100.0 s", "outside the recording"):
        assert w in msg, (w, msg)
