"""ROS 1 bags and ROS 2 bag folders holding ``sensor_msgs/LaserScan`` messages.

Read with the pure-Python ``rosbags`` package [1]_ (no ROS installation needed):
:class:`rosbags.highlevel.AnyReader` opens ROS 1 ``.bag`` files and ROS 2 bag folders
(``metadata.yaml`` + ``.db3``/``.mcap``) alike.

Conventions (also in ``docs/formats.md``)
-----------------------------------------
Topic
    One LaserScan topic is read per call.  ``topic`` may be given with or without the
    leading ``/``.  When it is omitted and the bag holds exactly one LaserScan topic, that
    one is used; otherwise a :class:`~gaitval.errors.FileFormatError` lists the LaserScan
    topics to choose from (the trial sheet's ``sensor_topic`` column).
Time
    ``ScanSeries.t`` is ``header.stamp`` (``sec + nanosec * 1e-9``, seconds since the
    epoch of the recording computer: the sensor driver's clock), in bag order.  Only when
    every stamp is zero (a driver that leaves them empty) the bag's receive time is used
    instead, and ``meta["time_source"]`` says ``bag_receive_time`` (else ``header.stamp``).
    Duplicate and non-monotonic stamps are reported in ``timestamp_issues``, never
    reordered.
Ranges
    Converted to float64 metres; inf, NaN, zero, below ``range_min`` and above
    ``range_max`` (of the first message) become NaN, the one "no return" value
    (:func:`gaitval.io.scanlog.clean_ranges`); the number mapped is ``n_no_return_raw``.
Geometry
    ``angle_min`` and ``angle_increment`` come from the first message; a change of beam
    count, ``angle_min`` or ``angle_increment`` within the topic is a FileFormatError.
Short loads (errors)
    The messages read must be the messages the bag's index lists: for every connection
    of the topic, the connection's message count (ROS 1 chunk infos, ROS 2
    ``metadata.yaml``) and, in a ROS 1 bag, the index records after the chunks
    (:mod:`gaitval.io.rosbag_check`); a ROS 1 bag's ``chunk_count`` and ``conn_count`` must
    match the chunk, chunk-info and connection records found.  Any disagreement is a
    FileFormatError naming the counts: a bag that loads short is never used.
Short loads (warnings)
    Two things a recording can really do are warnings, logged and listed in
    ``meta["warnings"]`` (``gaitval inspect`` prints them): a gap between two scans longer
    than :data:`GAP_FACTOR` times the median scan period, and a topic whose receive times
    cover less than :data:`COVERAGE` of the bag's span while other topics cover it (a
    scan count that drops against its neighbours).

References
----------
.. [1] Ternig, M. et al. rosbags: pure Python library to read, modify, convert and write
   rosbag files. https://gitlab.com/ternaris/rosbags
.. [2] ROS ``sensor_msgs/LaserScan`` message definition.
   https://docs.ros.org/en/api/sensor_msgs/html/msg/LaserScan.html
"""
from __future__ import annotations

import logging
from pathlib import Path
from typing import Any

import numpy as np

from gaitval.errors import FileFormatError
from gaitval.io.guard import loader
from gaitval.io.scanlog import (MAX_SCAN_TIME_S, check_scan_geometry, check_timestamps,
                                clean_ranges)
from gaitval.types import ScanSeries

LASERSCAN = "sensor_msgs/msg/LaserScan"
_ANGLE_TOL = 1e-6   # rad: tolerance for "the scan geometry changed"
#: a gap longer than this many median scan periods is a warning (the real bags in
#: ``realdata/lrs`` have none above 1.22)
GAP_FACTOR = 5.0
#: a topic whose receive times cover less than this share of the bag's span is a warning
#: (the real bags' topics cover >= 99.7 %)
COVERAGE = 0.9
log = logging.getLogger(__name__)


def is_rosbag(path: str | Path) -> bool:
    """True for a ``.bag`` file (ROS 1) or a ROS 2 bag folder (``metadata.yaml`` inside)."""
    p = Path(path)
    return (p.is_file() and p.suffix == ".bag") or (p.is_dir() and (p / "metadata.yaml").is_file())


def _open(path: Path, trial: str | None):
    from rosbags.highlevel import AnyReader
    from rosbags.typesys import Stores, get_typestore

    if not path.exists():
        raise FileFormatError("ROS bag not found", path=path, trial=trial)
    if path.is_file():
        # ROS 1: the magic line and every record's header and length checked (seeking over
        # the data, never holding it), and the index against the records, before the bag
        # library reads anything: it reads the whole index into memory first, 2 GB for a
        # 1 GB file of zeros
        from gaitval.io.rosbag_check import check_structure
        check_structure(path, trial)
    try:
        reader = AnyReader([path], default_typestore=get_typestore(Stores.ROS2_HUMBLE))
        reader.open()
    except Exception as exc:  # rosbags raises AnyReaderError / ReaderError / OSError
        raise FileFormatError(f"not a readable ROS bag: {_exc_text(exc)}",
                              path=path, trial=trial) from None
    return reader


def _exc_text(exc: BaseException) -> str:
    """A library's exception as text; one without a message (a bare ``assert`` of the
    bag library on a field it did not expect) says what it is instead of nothing."""
    text = str(exc).strip()
    if isinstance(exc, AssertionError) or not text:
        return (f"the bag library's own consistency check failed ({type(exc).__name__}"
                f"{': ' + text if text else ''}): a field of a record or message holds a "
                "value the format does not allow")
    return f"{type(exc).__name__}: {text}"


def _norm(topic: str) -> str:
    return topic.lstrip("/")


def _pick_topic(reader, topic: str | None, path: Path, trial: str | None) -> str:
    scans = sorted({c.topic for c in reader.connections if c.msgtype == LASERSCAN})
    if topic is not None and str(topic).strip():
        hits = [s for s in scans if _norm(s) == _norm(str(topic).strip())]
        if hits:
            return hits[0]
        others = sorted({c.topic for c in reader.connections})
        problem = (f"topic {topic!r} is not a LaserScan topic of this bag; LaserScan topics: "
                   f"{scans or 'none'}" + ("" if topic in others else
                                           f"; all topics: {others}"))
        raise FileFormatError(problem, path=path, trial=trial,
                              hint="set sensor_topic in the trial sheet")
    if len(scans) == 1:
        return scans[0]
    if not scans:
        others = sorted(f"{c.topic} ({c.msgtype})" for c in reader.connections)
        raise FileFormatError(f"bag has no {LASERSCAN} topic; topics: {others or 'none'}",
                              path=path, trial=trial)
    raise FileFormatError(f"bag has several LaserScan topics {scans}; choose one",
                          path=path, trial=trial, hint="set sensor_topic in the trial sheet")


def _read_topic(reader, topic: str, path: Path, trial: str | None) -> dict[str, Any]:
    """Raw arrays of one LaserScan topic (ranges in metres, not yet cleaned)."""
    conns = [c for c in reader.connections if c.topic == topic and c.msgtype == LASERSCAN]
    stamps, recv, rows = [], [], []
    per_conn: dict[int, int] = {}
    first = None
    frame_ids: set[str] = set()
    scan_times, time_incs = [], []
    try:
        for k, (con, ts, raw) in enumerate(reader.messages(connections=conns)):
            m = reader.deserialize(raw, con.msgtype)
            with np.errstate(invalid="ignore"):   # a signalling NaN: no return, cleaned
                r = np.asarray(m.ranges, dtype=np.float64)
            geo = (r.size, float(m.angle_min), float(m.angle_increment))
            if first is None:
                first = m
                geo0 = geo
            elif geo[0] != geo0[0]:
                raise FileFormatError(f"beam count changes within topic {topic}: scan 0 has "
                                      f"{geo0[0]} beams, scan {k} has {geo[0]}",
                                      path=path, trial=trial)
            elif abs(geo[1] - geo0[1]) > _ANGLE_TOL or abs(geo[2] - geo0[2]) > _ANGLE_TOL:
                raise FileFormatError(f"scan geometry changes within topic {topic} at scan "
                                      f"{k}: angle_min/increment {geo0[1]:.6g}/{geo0[2]:.6g}"
                                      f" -> {geo[1]:.6g}/{geo[2]:.6g} rad",
                                      path=path, trial=trial)
            per_conn[con.id] = per_conn.get(con.id, 0) + 1
            stamps.append(int(m.header.stamp.sec) * 1_000_000_000 + int(m.header.stamp.nanosec))
            recv.append(int(ts))
            rows.append(r)
            frame_ids.add(str(m.header.frame_id))
            scan_times.append(float(m.scan_time))
            time_incs.append(float(m.time_increment))
    except FileFormatError:
        raise
    except Exception as exc:
        raise FileFormatError(f"cannot decode LaserScan messages on {topic}: "
                              f"{_exc_text(exc)}", path=path, trial=trial) from None
    if first is None:
        raise FileFormatError(f"topic {topic} holds no messages", path=path, trial=trial)
    _check_message_counts(reader, conns, per_conn, topic, path, trial)
    stamps_ns = np.asarray(stamps, dtype=np.int64)
    if np.all(stamps_ns == 0):
        t_ns, source = np.asarray(recv, dtype=np.int64), "bag_receive_time"
    else:
        t_ns, source = stamps_ns, "header.stamp"
    # split into whole seconds and the rest before converting, to keep ns resolution
    t = (t_ns // 1_000_000_000).astype(np.float64) + (t_ns % 1_000_000_000) * 1e-9
    return {
        "t": t, "raw": np.vstack(rows), "angle_min": float(first.angle_min),
        "angle_increment": float(first.angle_increment),
        "range_min": float(first.range_min), "range_max": float(first.range_max),
        "time_source": source, "frame_ids": sorted(frame_ids),
        "scan_time_s": float(np.median(scan_times)),
        "time_increment_s": float(np.median(time_incs)),
        "recv_span_s": (recv[-1] - recv[0]) * 1e-9,
    }


def _check_message_counts(reader, conns, per_conn: dict[int, int], topic: str, path: Path,
                          trial: str | None) -> None:
    """The messages read against the index (module notes, "Short loads (errors)")."""
    for c in conns:
        listed, got = int(c.msgcount), per_conn.get(c.id, 0)
        if listed != got:
            raise FileFormatError(f"the bag's index disagrees with its contents: topic "
                                  f"{topic} (connection {c.id}) lists {listed} messages, "
                                  f"{got} were read", path=path, trial=trial,
                                  hint="reindex it (`rosbag reindex`) or re-record it")
    if path.is_file():                                           # ROS 1: walk the records
        from gaitval.io.rosbag_check import check_counts
        check_counts(path, trial, topic, per_conn, [c.id for c in conns])


def _short_load_warnings(d: dict, topic: str, bag_span_s: float, n_topics: int
                         ) -> list[str]:
    """Gaps and a short coverage (module notes, "Short loads (warnings)")."""
    out = []
    dt = np.diff(d["t"])
    good = dt[dt > 0]
    if good.size:
        period = float(np.median(good))
        long = np.flatnonzero(dt > GAP_FACTOR * period)
        if long.size:
            k = int(long[np.argmax(dt[long])])
            out.append(f"topic {topic}: {long.size} gap(s) longer than {GAP_FACTOR:g} x "
                       f"the median scan period ({period:.4g} s); the longest is "
                       f"{dt[k]:.3g} s after scan {k} of {len(d['t'])}")
    if n_topics > 1 and bag_span_s > 0 and d["recv_span_s"] < COVERAGE * bag_span_s:
        out.append(f"topic {topic}: its {len(d['t'])} scans cover {d['recv_span_s']:.3g} s "
                   f"of the bag's {bag_span_s:.3g} s (less than {COVERAGE:.0%}); scans may "
                   "be missing")
    return out


@loader("ROS bag")
def read_rosbag_scans(path: str | Path, topic: str | None = None, *,
                      trial: str | None = None) -> ScanSeries:
    """Read one ``sensor_msgs/LaserScan`` topic of a ROS 1 bag or ROS 2 bag folder.

    Parameters
    ----------
    path : str or Path
        ``.bag`` file (ROS 1) or ROS 2 bag folder.
    topic : str, optional
        LaserScan topic (with or without leading ``/``); may be omitted when the bag has
        exactly one.
    trial : str, optional
        Trial id, named in error messages.

    Returns
    -------
    ScanSeries
        ``t`` (header stamps in seconds, bag order), ``ranges`` (n_scans, n_beams) metres
        with NaN for no return, ``angle_min``, ``angle_increment``, ``range_min``,
        ``range_max``, ``source`` (``path#topic``), ``timestamp_issues``,
        ``n_no_return_raw``; ``meta`` has ``topic``, ``frame_id``, ``time_source``,
        ``scan_time_s``, ``time_increment_s``, ``warnings`` (gaps, short coverage).

    Raises
    ------
    FileFormatError
        Unreadable bag, missing/ambiguous topic, undecodable messages, a beam count /
        angle change within the topic, or messages read that disagree with the bag's
        index (see the module notes).
    """
    path = Path(path)
    reader = _open(path, trial)
    try:
        chosen = _pick_topic(reader, topic, path, trial)
        d = _read_topic(reader, chosen, path, trial)
        bag_span_s = (reader.end_time - reader.start_time) * 1e-9 if reader.connections \
            else 0.0
        n_topics = len({c.topic for c in reader.connections})
    finally:
        reader.close()
    _check_geometry(d, chosen, path, trial)
    warnings = _short_load_warnings(d, chosen, bag_span_s, n_topics)
    for w in warnings:
        log.warning("%s: %s", path, w)
    ranges, n_bad = clean_ranges(d["raw"], d["range_min"], d["range_max"])
    return ScanSeries(
        t=d["t"], ranges=ranges, angle_min=d["angle_min"],
        angle_increment=d["angle_increment"], range_min=d["range_min"],
        range_max=d["range_max"], sensor_model="unknown", mounting_height_m=None,
        source=f"{path}#{chosen}", timestamp_issues=check_timestamps(d["t"]),
        n_no_return_raw=n_bad,
        meta={"topic": chosen, "frame_id": ",".join(d["frame_ids"]),
              "time_source": d["time_source"], "scan_time_s": d["scan_time_s"],
              "time_increment_s": d["time_increment_s"], "format": "rosbag",
              "warnings": warnings})


def _check_geometry(d: dict, topic: str, path: Path, trial: str | None) -> None:
    """Finite angles and valid ranges in the first message (what every scan is read with)."""
    where = f"LaserScan topic {topic}, first message"
    for key in ("angle_min", "angle_increment", "range_min", "range_max"):
        if not np.isfinite(d[key]):
            raise FileFormatError(f"{where}: {key} is {d[key]!r}", path=path, trial=trial)
    if d["angle_increment"] == 0:
        raise FileFormatError(f"{where}: angle_increment is 0", path=path, trial=trial)
    if not 0 <= d["range_min"] < d["range_max"]:
        raise FileFormatError(f"{where}: range_min {d['range_min']:g} and range_max "
                              f"{d['range_max']:g} do not make a valid range", path=path,
                              trial=trial)
    if not np.all(np.isfinite(d["t"])):
        raise FileFormatError(f"{where}: timestamps are not finite", path=path, trial=trial)
    check_scan_geometry(f"LaserScan topic {topic}", d["raw"].shape[1], d["angle_min"],
                        d["angle_increment"], d["time_increment_s"], path, trial)
    if not (np.isfinite(d["scan_time_s"]) and 0 <= d["scan_time_s"] <= MAX_SCAN_TIME_S):
        raise FileFormatError(f"LaserScan topic {topic}: the median scan_time is "
                              f"{d['scan_time_s']!r} s; it must be finite, >= 0 (0: not "
                              f"stated) and at most {MAX_SCAN_TIME_S:g} s", path=path,
                              trial=trial)


def scan_summary(s: ScanSeries) -> dict[str, Any]:
    """Key numbers of a scan series (JSON-serialisable), shared by bag and scan-log describe."""
    dt = np.diff(s.t)
    good = dt[dt > 0]
    n_cells = s.ranges.size
    return {
        "n_scans": s.n_scans,
        "n_beams": s.n_beams,
        "angle_min_deg": float(np.degrees(s.angle_min)),
        "angle_max_deg": float(np.degrees(s.angle_max)),
        "angle_increment_deg": float(np.degrees(s.angle_increment)),
        "rate_hz": float(1.0 / np.median(good)) if good.size else float("nan"),
        "t_start_s": float(s.t[0]) if s.n_scans else float("nan"),
        "duration_s": float(s.t[-1] - s.t[0]) if s.n_scans else 0.0,
        "range_min_m": float(s.range_min),
        "range_max_m": float(s.range_max),
        "observed_range_min_m": float(np.nanmin(s.ranges)) if n_cells > s.n_no_return_raw
        else float("nan"),
        "observed_range_max_m": float(np.nanmax(s.ranges)) if n_cells > s.n_no_return_raw
        else float("nan"),
        "n_no_return": int(s.n_no_return_raw),
        "no_return_fraction": float(s.n_no_return_raw / n_cells) if n_cells else 0.0,
        "n_timestamp_issues": int(len(s.timestamp_issues)),
        "timestamp_issues": [{"index": int(r.index), "t_s": float(r.t_s),
                              "problem": str(r.problem)}
                             for r in s.timestamp_issues.head(20).itertuples(index=False)],
    }


@loader("ROS bag")
def describe_rosbag(path: str | Path, topic: str | None = None, *,
                    trial: str | None = None) -> dict[str, Any]:
    """What gaitval sees in a bag, as a JSON-serialisable dict (for ``gaitval inspect``).

    Keys: ``kind`` ("rosbag"), ``path``, ``ros_version`` (1 or 2), ``duration_s``,
    ``topics`` (list of ``{topic, msgtype, count}``), ``scans`` (LaserScan topic ->
    :func:`scan_summary` dict plus ``frame_id``, ``time_source``).  With ``topic`` only that
    topic is summarised, otherwise every LaserScan topic.
    """
    path = Path(path)
    reader = _open(path, trial)
    try:
        topics = {}
        for c in reader.connections:
            key = (c.topic, c.msgtype)
            topics[key] = topics.get(key, 0) + int(c.msgcount)
        scan_topics = sorted({c.topic for c in reader.connections if c.msgtype == LASERSCAN})
        if topic is not None:
            scan_topics = [_pick_topic(reader, topic, path, trial)]
        duration = float(reader.duration) * 1e-9 if reader.connections else 0.0
        ros_version = 2 if path.is_dir() else 1
    finally:
        reader.close()
    scans = {}
    for tp in scan_topics:
        s = read_rosbag_scans(path, tp, trial=trial)
        scans[tp] = {**scan_summary(s), "frame_id": s.meta["frame_id"],
                     "time_source": s.meta["time_source"],
                     "warnings": list(s.meta["warnings"])}
    return {
        "kind": "rosbag",
        "path": str(path),
        "ros_version": ros_version,
        "duration_s": duration,
        "topics": [{"topic": k[0], "msgtype": k[1], "count": n}
                   for k, n in sorted(topics.items())],
        "scans": scans,
        "warnings": [w for s in scans.values() for w in s["warnings"]],
    }
