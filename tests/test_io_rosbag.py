"""ROS bag loader: the two real ROS 1 bags (../shared/realdata/lrs) and ROS 2 bags written
here with ``rosbags``' own writer.

Reference numbers are from realdata/README.md: demo_stationary_simple_environment.bag has
1265 scans on ``/scan``, 512 beams, -90 deg ... +89.6 deg in 0.352 deg steps, about 10 Hz;
positive_1.bag has 400 scans on ``right_scan``, 768 beams, -135 deg ... +134.6 deg, 7.5 Hz.
The raw "no return" count is computed here independently from the deserialised messages.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from gaitval.errors import FileFormatError
from gaitval.io.inspect import describe, format_description
from gaitval.io.rosbag import describe_rosbag, read_rosbag_scans

BAGS = {
    # file: (topic, scans, beams, angle_min_deg, angle_max_deg, rate_hz)
    "demo_stationary_simple_environment.bag": ("/scan", 1265, 512, -90.0, 89.6, 10.0),
    "positive_1.bag": ("right_scan", 400, 768, -135.0, 134.6, 7.5),
}


@pytest.fixture(scope="module")
def bags(realdata):
    return {name: read_rosbag_scans(realdata / "lrs" / name, spec[0])
            for name, spec in BAGS.items()}


def raw_no_return(path: Path, topic: str) -> tuple[int, int]:
    """(count of inf/NaN/<=0/out-of-[range_min, range_max] beams, count of inf beams),
    read with rosbags directly, independently of gaitval."""
    from rosbags.highlevel import AnyReader

    bad = n_inf = 0
    with AnyReader([path]) as r:
        conns = [c for c in r.connections if c.topic == topic]
        for con, _, raw in r.messages(connections=conns):
            m = r.deserialize(raw, con.msgtype)
            x = np.asarray(m.ranges, dtype=np.float64)
            n_inf += int(np.isinf(x).sum())
            with np.errstate(invalid="ignore"):
                bad += int((~np.isfinite(x) | (x <= 0) | (x < m.range_min)
                            | (x > m.range_max)).sum())
    return bad, n_inf


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(BAGS))
def test_real_bag_geometry(bags, name):
    topic, n_scans, n_beams, amin, amax, rate = BAGS[name]
    s = bags[name]
    assert s.n_scans == n_scans and s.n_beams == n_beams
    assert s.ranges.shape == (n_scans, n_beams)
    assert np.degrees(s.angle_min) == pytest.approx(amin, abs=1e-3)
    assert np.degrees(s.angle_max) == pytest.approx(amax, abs=0.05)
    assert np.degrees(s.angle_increment) == pytest.approx(0.352, abs=5e-4)
    assert s.meta["topic"] == topic and s.source.endswith("#" + topic)
    assert s.meta["time_source"] == "header.stamp"
    assert 1 / np.median(np.diff(s.t)) == pytest.approx(rate, rel=0.02)
    assert s.timestamp_issues.empty


@pytest.mark.realdata
@pytest.mark.parametrize("name", sorted(BAGS))
def test_real_bag_no_return_is_nan(bags, realdata, name):
    s = bags[name]
    bad, n_inf = raw_no_return(realdata / "lrs" / name, BAGS[name][0])
    assert not np.isinf(s.ranges).any()
    assert int(np.isnan(s.ranges).sum()) == bad == s.n_no_return_raw
    assert n_inf > s.n_scans                    # README: hundreds of inf per scan (demo bag)
    ok = s.ranges[~np.isnan(s.ranges)]
    assert ok.min() >= s.range_min and ok.max() <= s.range_max


@pytest.mark.realdata
def test_topic_choice_and_errors(realdata):
    p = realdata / "lrs" / "positive_1.bag"
    s = read_rosbag_scans(p, "/right_scan")                    # leading slash tolerated
    assert s.meta["topic"] == "right_scan" and s.n_scans == 400
    assert read_rosbag_scans(p).n_scans == 400                 # the only LaserScan topic
    with pytest.raises(FileFormatError, match="right_scan") as exc:
        read_rosbag_scans(p, "/scan", trial="S2_T4")
    assert "positive_1.bag" in str(exc.value) and "S2_T4" in str(exc.value)


def test_not_a_bag(tmp_path):
    f = tmp_path / "x.bag"
    f.write_bytes(b"#ROSBAG V2.0\nthis is not a bag")
    with pytest.raises(FileFormatError, match="x.bag"):
        read_rosbag_scans(f)
    with pytest.raises(FileFormatError, match="not found"):
        read_rosbag_scans(tmp_path / "absent.bag")


# -- ROS 2 bags written with rosbags' writer ----------------------------------------------

def write_ros2_bag(path: Path, topics: dict[str, list[tuple[int, int, np.ndarray]]],
                   extra_topic: bool = False) -> Path:
    """topics: name -> list of (stamp_ns, receive_ns, ranges) LaserScan messages."""
    from rosbags.rosbag2 import Writer
    from rosbags.typesys import Stores, get_typestore

    ts = get_typestore(Stores.ROS2_HUMBLE)
    LS = ts.types["sensor_msgs/msg/LaserScan"]
    H = ts.types["std_msgs/msg/Header"]
    T = ts.types["builtin_interfaces/msg/Time"]
    S = ts.types["std_msgs/msg/String"]
    with Writer(path, version=9) as w:
        for name, msgs in topics.items():
            con = w.add_connection(name, LS.__msgtype__, typestore=ts)
            for stamp, recv, r in msgs:
                r = np.asarray(r, dtype=np.float32)
                m = LS(header=H(stamp=T(sec=stamp // 10**9, nanosec=stamp % 10**9),
                                frame_id="laser"),
                       angle_min=-0.5, angle_max=-0.5 + 0.25 * (r.size - 1),
                       angle_increment=0.25, time_increment=0.0, scan_time=0.025,
                       range_min=0.1, range_max=10.0, ranges=r,
                       intensities=np.zeros(0, dtype=np.float32))
                w.write(con, recv, ts.serialize_cdr(m, LS.__msgtype__))
        if extra_topic:
            con = w.add_connection("/chatter", S.__msgtype__, typestore=ts)
            w.write(con, 1, ts.serialize_cdr(S(data="hi"), S.__msgtype__))
    return path


R5 = np.array([1.0, np.inf, 0.0, 20.0, 0.05])   # valid, inf, zero, > range_max, < range_min


def test_ros2_bag_ranges_and_stamps(tmp_path):
    # stamps 1.0, 1.1, 1.1 (duplicate), 1.05 (goes back) s; 5 beams, 4 of them "no return"
    stamps = [1_000_000_000, 1_100_000_000, 1_100_000_000, 1_050_000_000]
    p = write_ros2_bag(tmp_path / "b2", {"/scan": [(s, 10 + k, R5)
                                                   for k, s in enumerate(stamps)]},
                       extra_topic=True)
    s = read_rosbag_scans(p)
    assert s.n_scans == 4 and s.n_beams == 5
    assert np.allclose(s.t, [1.0, 1.1, 1.1, 1.05])             # file order, not sorted
    assert np.isnan(s.ranges[:, 1:]).all() and np.all(s.ranges[:, 0] == 1.0)
    assert s.n_no_return_raw == 16
    assert s.angle_min == -0.5 and s.angle_increment == 0.25
    assert list(s.timestamp_issues["problem"]) == ["duplicate", "non-monotonic"]
    assert list(s.timestamp_issues["index"]) == [2, 3]
    d = describe(p)
    assert d["ros_version"] == 2 and d["scans"]["/scan"]["n_timestamp_issues"] == 2
    assert {"topic": "/chatter", "msgtype": "std_msgs/msg/String", "count": 1} in d["topics"]


def test_ros2_zero_stamps_fall_back_to_receive_time(tmp_path):
    p = write_ros2_bag(tmp_path / "z", {"/scan": [(0, 2_000_000_000 + k * 25_000_000, R5)
                                                  for k in range(3)]})
    s = read_rosbag_scans(p)
    assert s.meta["time_source"] == "bag_receive_time"
    assert np.allclose(s.t, [2.0, 2.025, 2.05])


def test_ros2_beam_count_change_and_ambiguous_topic(tmp_path):
    p = write_ros2_bag(tmp_path / "bc", {"/scan": [(10**9, 1, R5), (2 * 10**9, 2, R5[:4])]})
    with pytest.raises(FileFormatError, match="beam count changes"):
        read_rosbag_scans(p)
    q = write_ros2_bag(tmp_path / "two", {"/front": [(10**9, 1, R5)],
                                          "/rear": [(10**9, 1, R5)]})
    with pytest.raises(FileFormatError, match="several LaserScan topics") as exc:
        read_rosbag_scans(q)
    assert "/front" in str(exc.value) and "/rear" in str(exc.value)
    assert read_rosbag_scans(q, "rear").meta["topic"] == "/rear"
    assert set(describe_rosbag(q)["scans"]) == {"/front", "/rear"}
    r = write_ros2_bag(tmp_path / "none", {}, extra_topic=True)
    with pytest.raises(FileFormatError, match="no sensor_msgs/msg/LaserScan topic"):
        read_rosbag_scans(r)


@pytest.mark.realdata
def test_describe_real_bag(realdata):
    d = describe(realdata / "lrs" / "demo_stationary_simple_environment.bag")
    json.dumps(d, allow_nan=False)
    assert d["kind"] == "rosbag" and d["ros_version"] == 1
    assert d["topics"] == [{"topic": "/scan", "msgtype": "sensor_msgs/msg/LaserScan",
                            "count": 1265}]
    s = d["scans"]["/scan"]
    assert (s["n_scans"], s["n_beams"]) == (1265, 512)
    assert s["angle_min_deg"] == pytest.approx(-90.0, abs=1e-3)
    assert s["angle_increment_deg"] == pytest.approx(0.3516, abs=1e-4)
    assert s["rate_hz"] == pytest.approx(10.0, rel=0.02)
    assert s["range_min_m"] == pytest.approx(0.02) and s["range_max_m"] == pytest.approx(5.6)
    assert s["n_no_return"] > 1265
    text = format_description(d)
    assert "1265" in text and "512" in text and "/scan" in text


# -- issue 33: short loads are errors (index vs contents) or loud warnings (gaps) ----------

def _patch_u32(data: bytes, field: bytes, value: int, start: int = 0) -> bytes:
    import struct
    b = bytearray(data)
    i = b.find(field, start) + len(field)
    struct.pack_into("<I", b, i, value)
    return bytes(b)


@pytest.mark.realdata
@pytest.mark.parametrize("patch, message", [
    ("chunk_count", "the bag header announces chunk_count=1, the file holds 6 chunk records"),
    ("chunk_count=0", "the bag header announces chunk_count=0, the file holds 6 chunk records"),
    ("conn", r"list messages of connection\(s\) \[7\], which the bag does not define"),
    ("info", r"topic /left_scan \(connection 0\): the index records list 435 messages, the "
             "chunk infos 430, and 435 were read"),
])
def test_bag_whose_index_disagrees_is_refused_with_counts(realdata, tmp_path, patch,
                                                         message):
    """The issue's reproducers: chunk_count=1 loaded 82 of 435 scans per topic, and a
    corrupted connection id dropped a topic, both with rc 0 and "timestamps clean"."""
    import struct

    from gaitval.cli import main
    from gaitval.io.rosbag_check import _fields
    data = (realdata / "lrs" / "negative_2.bag").read_bytes()
    records, pos = [], 13                      # (start, fields, data start) of each record
    while pos < len(data):
        hlen = struct.unpack_from("<I", data, pos)[0]
        dlen = struct.unpack_from("<I", data, pos + 4 + hlen)[0]
        records.append((pos, _fields(data[pos + 4:pos + 4 + hlen], pos), pos + 8 + hlen))
        pos += 8 + hlen + dlen
    if patch.startswith("chunk_count"):                 # 0: a bag without any topic
        data = _patch_u32(data, b"chunk_count=", 0 if patch.endswith("0") else 1)
    elif patch == "conn":                      # the first index record after a chunk
        at = next(r[0] for r in records if r[1]["op"] == b"\x04")
        data = _patch_u32(data, b"conn=", 7, at)
    else:                                      # the first chunk info's count of conn 0
        at = next(r for r in records if r[1]["op"] == b"\x06")
        b = bytearray(data)
        for k in range(struct.unpack("<I", at[1]["count"])[0]):
            conn, n = struct.unpack_from("<II", b, at[2] + 8 * k)
            if conn == 0:
                struct.pack_into("<I", b, at[2] + 8 * k + 4, n - 5)
        data = bytes(b)
    path = tmp_path / "broken.bag"
    path.write_bytes(data)
    with pytest.raises(FileFormatError, match=message) as exc:
        read_rosbag_scans(path, "/left_scan", trial="S03_T1")
    assert str(path) in str(exc.value) and "S03_T1" in str(exc.value)
    assert main(["inspect", str(path)]) == 1


@pytest.mark.realdata
def test_real_bags_pass_the_index_checks_without_warnings(realdata):
    from gaitval.io.rosbag_check import walk_bag1
    s = walk_bag1(realdata / "lrs" / "negative_2.bag")
    assert (s["chunk_count"], s["chunks"], s["chunk_infos"]) == (6, 6, 6)
    assert s["index_counts"] == s["info_counts"] == {0: 435, 1: 435, 2: 434}
    for topic, n in (("/left_scan", 435), ("/right_scan", 434)):
        got = read_rosbag_scans(realdata / "lrs" / "negative_2.bag", topic)
        assert got.n_scans == n and got.meta["warnings"] == []


def test_ros2_message_count_that_disagrees_is_refused(tmp_path):
    p = write_ros2_bag(tmp_path / "mc", {"/scan": [(10**9 + k * 10**8, 1 + k, R5)
                                                   for k in range(10)]})
    meta = (p / "metadata.yaml").read_text()
    assert "message_count: 10" in meta
    (p / "metadata.yaml").write_text(meta.replace("message_count: 10", "message_count: 12"))
    with pytest.raises(FileFormatError, match="lists 12 messages, 10 were read"):
        read_rosbag_scans(p)


def test_a_long_gap_is_a_loud_warning(tmp_path, caplog):
    stamps = [10**9 + k * 25_000_000 for k in range(40)]
    stamps = stamps[:20] + [s + 2 * 10**9 for s in stamps[20:]]      # a 2.025 s gap
    p = write_ros2_bag(tmp_path / "gap", {"/scan": [(s, s, R5) for s in stamps]})
    with caplog.at_level("WARNING", logger="gaitval.io.rosbag"):
        s = read_rosbag_scans(p)
    assert s.n_scans == 40
    want = "1 gap(s) longer than 5 x the median scan period (0.025 s); the longest is " \
           "2.02 s after scan 19 of 40"
    assert s.meta["warnings"] == [f"topic /scan: {want}"]
    assert want in caplog.text
    d = describe(p)
    assert d["warnings"] == [f"topic /scan: {want}"]
    assert f"WARNING: topic /scan: {want}" in format_description(d)
    q = write_ros2_bag(tmp_path / "even", {"/scan": [(s, s, R5) for s in stamps[:20]]})
    assert read_rosbag_scans(q).meta["warnings"] == []
    assert "warnings:     none" in format_description(describe(q))
