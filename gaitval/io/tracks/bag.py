"""ROS 1/2 bag topics of leg_tracker and people_msgs: a tracker's people topic as exchange
rows, leg_tracker's leg detections, and people rows as leg rows.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import FORMAT, SIDES, VERSION, _err


#: tracker output types read from bags (ROS 2 style names, as rosbags reports them)
BAG_PEOPLE_TYPES = ("leg_tracker/msg/PersonArray", "people_msgs/msg/People",
                    "geometry_msgs/msg/PoseArray")
BAG_LEG_DETECTIONS = "leg_tracker/msg/LegArray"


def _bag_topic(reader, topic, known, p, trial):
    """The connections of the tracker topic to read: ``topic`` (an error listing the
    tracker topics and all topics when the bag has no such topic), or the bag's only
    topic of a type in ``known``."""
    from gaitval.io.rosbag import _norm

    cands = [c for c in reader.connections if c.msgtype in known]
    if topic is not None and str(topic).strip():
        conns = [c for c in reader.connections if _norm(c.topic) == _norm(str(topic))]
        if not conns:
            raise _err(p, f"topic {topic!r} is not in this bag; tracker topics: "
                       f"{sorted({c.topic for c in cands}) or 'none'}; all topics: "
                       f"{sorted({c.topic for c in reader.connections})}", trial)
        return conns
    topics = sorted({c.topic for c in cands})
    if len(topics) != 1:
        raise _err(p, f"{'no' if not topics else 'several'} tracker topic(s) of type "
                   f"{', '.join(known)} in this bag"
                   f"{': ' + str(topics) if topics else ''}", trial, hint="name the topic")
    return [c for c in cands if c.topic == topics[0]]


def _scan_frames(reader) -> set:
    from gaitval.io.rosbag import LASERSCAN

    scans = [c for c in reader.connections if c.msgtype == LASERSCAN]
    return {str(reader.deserialize(raw, con.msgtype).header.frame_id)
            for con, _, raw in reader.messages(connections=scans)}


def _check_frames(p, name, frames, scan_frames, trial) -> None:
    """The topic's header frame must be the laser's (gaitval reads no /tf)."""
    if not scan_frames:
        raise _err(p, f"no LaserScan topic in this bag: the frame of {name} "
                   f"({', '.join(sorted(frames))}) cannot be checked against the laser's",
                   trial, hint="record the scans with the tracker's output")
    if frames != scan_frames or len(frames) != 1:
        raise _err(p, f"topic {name} is in frame(s) {sorted(frames)} but the scans in "
                   f"{sorted(scan_frames)}; gaitval does not transform between frames",
                   trial, hint="publish the tracks in the laser frame")


def _stamp(m) -> float:
    return int(m.header.stamp.sec) + int(m.header.stamp.nanosec) * 1e-9


def read_bag_tracks(path: str | Path, topic: str | None = None, *,
                    trial: str | None = None) -> tuple[pd.DataFrame, dict]:
    """A tracker's people topic of a ROS bag as exchange-format rows (``person``).

    ``leg_tracker/PersonArray`` (leg_tracker's ``/people_tracked``: ``header``,
    ``people[]`` with ``pose`` and ``id``) and ``people_msgs/People`` (``header``,
    ``people[]`` with ``name`` and ``position``).  The message definitions are taken from
    the bag (a ROS 1 bag embeds them; as :mod:`gaitval.io.annotations_bag` does), so
    nothing needs ROS installed.  Times are the messages' ``header.stamp`` (the clock of
    the scans they were tracked in: ``clock: sensor``); positions in metres
    (``units: m``).  The header's ``frame_id`` must be the frame of the bag's LaserScan
    messages (``frame: sensor``): gaitval does not read ``/tf``.

    ``geometry_msgs/PoseArray`` (``header``, ``poses[]``): the pose's index in the array
    is its ``person`` id (``0``, ``1``, ...), for a tracker that publishes its two legs
    in a fixed order.

    ``leg_tracker/LegArray`` (``/detected_leg_clusters``) holds leg *detections* of one
    scan without identity or side, not tracks: it is refused with that reason (they are
    read by :func:`read_bag_leg_detections`).

    Returns
    -------
    (DataFrame, dict)
        Rows ``t_s, person, x, y`` (sorted by time and person, in metres; and ``msg``,
        the message's number on the topic, 1-based, which errors name) and the header
        (``format, version, units: m, frame: sensor, clock: sensor, source``), ready for
        :func:`~gaitval.io.tracks.write.write_tracks`.
    """
    p = Path(path)
    rows, frames, scan_frames, msgtype, name = _read_topic(
        p, topic, BAG_PEOPLE_TYPES + (BAG_LEG_DETECTIONS,), trial, _check_people_type,
        _people_rows)
    if not rows:
        raise _err(p, f"topic {name} holds no person", trial)
    _check_frames(p, name, frames, scan_frames, trial)
    df = pd.DataFrame(rows, columns=["t_s", "person", "x", "y", "msg"])
    _check_people(df, p, name, trial)
    df = df.sort_values(["t_s", "person"], kind="stable")     # msg: where errors point
    meta = {"format": FORMAT, "version": VERSION, "units": "m", "frame": "sensor",
            "clock": "sensor", "source": f"{msgtype} on {name}"}
    return df.reset_index(drop=True), meta


def _check_people_type(p: Path, name: str, msgtype: str, trial) -> None:
    """A tracker topic of people: not leg_tracker's detections, no other type."""
    if msgtype == BAG_LEG_DETECTIONS:
        raise _err(p, f"topic {name} holds {msgtype}: leg detections of one scan "
                   "without identity or side, not tracks", trial,
                   hint="record the tracker's people topic (leg_tracker/PersonArray, "
                   "/people_tracked) or write the legs' tracks as a *.tracks.csv; "
                   "detections are scored by 'gaitval leg-detections'")
    if msgtype not in BAG_PEOPLE_TYPES:
        raise _err(p, f"topic {name} holds {msgtype}, not one of "
                   f"{', '.join(BAG_PEOPLE_TYPES)}", trial)


def _read_topic(p: Path, topic, known: tuple, trial, check_type, read_rows):
    """Open the bag, pick its topic (:func:`_bag_topic` among the types ``known``), check
    the topic's type (``check_type(p, name, msgtype, trial)``) and read it
    (``read_rows(reader, conns, msgtype, p, name, trial) -> (rows, frames)``):
    ``(rows, frames, scan_frames, msgtype, name)``, the frames of the topic's messages
    and of the bag's LaserScans for :func:`_check_frames`."""
    from gaitval.io.annotations_bag import _register_custom_types
    from gaitval.io.rosbag import _open

    reader = _open(p, trial)
    try:
        _register_custom_types(reader)
        conns = _bag_topic(reader, topic, known, p, trial)
        msgtype, name = conns[0].msgtype, conns[0].topic
        check_type(p, name, msgtype, trial)
        scan_frames = _scan_frames(reader)
        rows, frames = read_rows(reader, conns, msgtype, p, name, trial)
    finally:
        reader.close()
    return rows, frames, scan_frames, msgtype, name


def _people_rows(reader, conns, msgtype: str, *_) -> tuple[list, set]:
    """``(t, person, x, y, message number)`` of every person of every message on the
    topic, and the messages' header frames."""
    rows, frames = [], set()
    for n, (con, _, raw) in enumerate(reader.messages(connections=conns)):
        m = reader.deserialize(raw, con.msgtype)
        t = _stamp(m)
        frames.add(str(m.header.frame_id))
        if msgtype == BAG_PEOPLE_TYPES[2]:          # PoseArray: the index is the id
            items = [(str(i), q.position) for i, q in enumerate(m.poses)]
        elif msgtype == BAG_PEOPLE_TYPES[0]:
            items = [(str(int(q.id)), q.pose.position) for q in m.people]
        else:
            items = [(str(q.name), q.position) for q in m.people]
        for pid, pos in items:
            rows.append((t, pid, float(pos.x), float(pos.y), n + 1))
    return rows, frames


def _check_people(df: pd.DataFrame, p: Path, name: str, trial) -> None:
    """Every person's position finite, no person twice at one time stamp."""
    bad = ~np.isfinite(df[["t_s", "x", "y"]].to_numpy()).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise _err(p, f"topic {name}, message {df['msg'].iloc[i]}: person "
                   f"{df['person'].iloc[i]!r} has a non-finite position", trial)
    dup = df.duplicated(["t_s", "person"])
    if dup.any():
        i = int(np.flatnonzero(dup.to_numpy())[0])
        raise _err(p, f"topic {name}, message {df['msg'].iloc[i]}: person "
                   f"{df['person'].iloc[i]!r} twice at time stamp {float(df['t_s'].iloc[i])!r} s",
                   trial)


def read_bag_leg_detections(path: str | Path, topic: str | None = None, *,
                            trial: str | None = None) -> tuple[pd.DataFrame, dict]:
    """leg_tracker's leg detections (``leg_tracker/LegArray``, ``/detected_leg_clusters``:
    ``header``, ``legs[]`` with ``position`` and ``confidence``) of a ROS 1/2 bag.

    A detection has no identity and no side: it is the input of a tracker, not a track.
    gaitval does not pair detections into left and right tracks (that pairing would be a
    tracker of gaitval's, not the external system's result); they are scored as
    detections only (:func:`gaitval.evaluate.leg_detections.detection_statistics`).

    Returns
    -------
    (DataFrame, dict)
        One row per detection: ``t_s`` (``header.stamp``, sensor clock), ``msg`` (the
        message's number on the topic, 1-based; a message without legs has no row),
        ``x_m``, ``y_m`` (laser frame, metres), ``confidence``; and
        ``{"source": "<type> on <topic>", "n_messages": N, "t_messages": [...]}``
        (every message's stamp, legs or not).

    Raises
    ------
    FileFormatError
        Naming the bag: a topic it does not have or of another type, a topic not in the
        laser's frame, no LaserScan to check that against, a non-finite position (naming
        the message).
    """
    p = Path(path)
    (rows, stamps), frames, scan_frames, msgtype, name = _read_topic(
        p, topic, (BAG_LEG_DETECTIONS,), trial, _check_legs_type, _leg_rows)
    if not stamps:
        raise _err(p, f"topic {name} has no message", trial)
    _check_frames(p, name, frames, scan_frames, trial)
    df = pd.DataFrame(rows, columns=["t_s", "msg", "x_m", "y_m", "confidence"])
    return df, {"source": f"{msgtype} on {name}", "n_messages": len(stamps),
                "t_messages": stamps}


def _check_legs_type(p: Path, name: str, msgtype: str, trial) -> None:
    if msgtype != BAG_LEG_DETECTIONS:
        raise _err(p, f"topic {name} holds {msgtype}, not {BAG_LEG_DETECTIONS}", trial)


def _leg_rows(reader, conns, msgtype, p, name, trial) -> tuple[tuple[list, list], set]:
    """``((rows, stamps), frames)``: ``(t, message number, x, y, confidence)`` of every
    leg of every message, every message's stamp, and the messages' header frames."""
    rows, frames, stamps = [], set(), []
    for n, (con, _, raw) in enumerate(reader.messages(connections=conns)):
        m = reader.deserialize(raw, con.msgtype)
        t = _stamp(m)
        stamps.append(t)
        frames.add(str(m.header.frame_id))
        for leg in m.legs:
            x, y = float(leg.position.x), float(leg.position.y)
            if not (math.isfinite(x) and math.isfinite(y)):
                raise _err(p, f"topic {name}, message {n + 1}: a leg has a non-finite "
                           "position", trial)
            rows.append((t, n + 1, x, y, float(leg.confidence)))
    return (rows, stamps), frames


def people_to_legs(rows: pd.DataFrame, legs: dict, *, path=None, trial: str | None = None,
                   topic: str = "") -> pd.DataFrame:
    """People rows (``t_s, person, x, y`` in metres, :func:`read_bag_tracks`) as leg rows
    (``t_s, side, x_m, y_m``, :func:`~gaitval.io.tracks.read.read_tracks`' columns, and
    ``msg`` when the people rows have it): ``legs`` maps each side to the person id that
    tracked it (``{"L": "1", "R": "2"}``; a PoseArray's index), for a tracker that
    publishes each leg as a person.  Other ids are dropped.  A time stamp where one leg's
    id is absent gets that leg without a position (not observed: the tracker had no track);
    an id that never appears is an error naming it."""
    if set(legs) != set(SIDES):
        raise _err(path, f"legs {dict(legs)!r} must map both sides L and R to a person id",
                   trial)
    ids = {str(v): k for k, v in legs.items()}
    if len(ids) != 2:
        raise _err(path, f"legs {dict(legs)!r}: L and R name the same person id", trial)
    present = set(rows["person"].astype(str))
    for side in SIDES:
        if str(legs[side]) not in present:
            raise _err(path, f"{topic + ': ' if topic else ''}leg {side} (person id "
                       f"{str(legs[side])!r}) is missing: no message holds it; ids present: "
                       f"{sorted(present)[:10]}", trial,
                       hint="set tracking.external.<method>.legs to the ids the tracker "
                       "gave the legs")
    r = rows[rows["person"].astype(str).isin(ids)]
    r = r.assign(side=r["person"].astype(str).map(ids))
    times = np.unique(rows["t_s"].to_numpy(float))
    full = pd.MultiIndex.from_product([times, list(SIDES)], names=["t_s", "side"])
    out = (r.set_index(["t_s", "side"])[["x", "y"]].reindex(full).reset_index()
           .rename(columns={"x": "x_m", "y": "y_m"}))
    if "msg" not in rows:
        return out[["t_s", "side", "x_m", "y_m"]]
    first = rows.drop_duplicates("t_s").set_index("t_s")["msg"]
    out["msg"] = out["t_s"].map(first).to_numpy(np.int64)     # the message of each time
    return out[["t_s", "side", "x_m", "y_m", "msg"]]
