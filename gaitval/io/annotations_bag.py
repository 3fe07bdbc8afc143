"""Hand-annotated person positions: a ROS bag topic or a position CSV (no motion capture).

A recording without mocap is scored against positions a rater clicked in the scans
(docs/legbench.md).  Two sources, one table (:data:`POSITION_COLUMNS`):

Bag topic (:func:`read_bag_annotations`)
    ``leg_tracker/Person`` (``geometry_msgs/Pose pose``, ``uint32 id``; one message per
    annotated person per scan), ``leg_tracker/PersonArray`` (``header``, ``people[]``) or
    ``people_msgs/People`` (``header``, ``people[]`` with ``name``, ``position``).  The
    message definitions of these custom types are taken from the bag itself (a ROS 1 bag
    embeds each connection's definition); nothing needs ROS installed.
CSV (:func:`read_position_csv`)
    ``# gaitval-positions v1`` on the first line, then columns ``t_s, x_m, y_m, id`` and an
    optional ``frame``: ``t_s`` on the sensor clock (the scans' header stamps), positions in
    metres in the laser frame (docs/formats_recordings.md).

Which scan an annotation belongs to (bag topics)
    The leg_tracker annotation tool (angusleigh/leg_tracker_benchmarks,
    ``annotate_rosbags.py``) writes each click at the bag time halfway between the scan it
    was made on and the next one, and the benchmark's CLEAR-MOT script counts every
    annotation with the last scan before it in bag order (Leigh et al., ICRA 2015).
    gaitval does the same: ``k`` is the index (in bag order) of the last scan on
    ``scan_topic`` whose *bag receive time* is before the annotation's.  The annotation's
    ``t_s`` is that scan's header stamp, i.e. the clock of the :class:`ScanSeries` the
    tracker sees.  (In ``person_following_outdoor_1.bag`` the scan header stamps run 130.28 s
    ahead of the bag receive times, so the two clocks must not be mixed.)
Frame
    ``leg_tracker/Person`` has no header.  Its frame is read from the tool's own display
    markers (``visualization_msgs/Marker`` with namespace ``<topic>_markers``, written
    with the same positions and the tool's fixed frame); failing that from a header of the
    annotation message; failing both, the scan's frame is assumed and ``meta
    ["frame_source"]`` says so.  An annotation frame other than the scan's is refused
    (gaitval does not read ``/tf``).

References
----------
Leigh, A.; Pineau, J.; Olmedo, N.; Zhang, H. Person tracking and following with 2D laser
scanners. IEEE ICRA 2015 (the annotated benchmark bags and their CLEAR-MOT evaluation).
"""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import write_text
from gaitval.io.guard import loader
from gaitval.io.rosbag import LASERSCAN, _norm, _open, _pick_topic

#: one row per annotated person and scan
POSITION_COLUMNS = ["k", "t_s", "x_m", "y_m", "id", "frame"]
POSITIONS_MAGIC = "# gaitval-positions v1"
#: annotation message types read from bags (ROS 2 style names, as rosbags reports them)
PERSON_TYPES = ("leg_tracker/msg/Person", "leg_tracker/msg/PersonArray",
                "people_msgs/msg/People")
MARKER = "visualization_msgs/msg/Marker"


def _register_custom_types(reader) -> None:
    """Register the bag's embedded definitions of types the default store lacks."""
    from rosbags.typesys import get_types_from_msg

    store = reader.typestore
    types: dict[str, Any] = {}
    for c in reader.connections:
        if c.msgtype in store.fielddefs or c.msgtype in types:
            continue
        data = getattr(c.msgdef, "data", c.msgdef)
        if data:
            types.update(get_types_from_msg(data, c.msgtype))
    if types:
        store.register(types)


def _persons(msg, msgtype: str) -> tuple[list[tuple[str, float, float]], str]:
    """(id, x, y) of the people in one annotation message, and its header frame ('')."""
    if msgtype == "leg_tracker/msg/Person":
        p = msg.pose.position
        return [(str(int(msg.id)), float(p.x), float(p.y))], ""
    frame = str(msg.header.frame_id)
    if msgtype == "leg_tracker/msg/PersonArray":
        return [(str(int(q.id)), float(q.pose.position.x), float(q.pose.position.y))
                for q in msg.people], frame
    return [(str(q.name), float(q.position.x), float(q.position.y)) for q in msg.people], frame


def _pick_annotation_topic(reader, topic: str | None, path: Path, trial: str | None) -> Any:
    cands = [c for c in reader.connections if c.msgtype in PERSON_TYPES]
    if topic is not None and str(topic).strip():
        hits = [c for c in reader.connections if _norm(c.topic) == _norm(str(topic))]
        if not hits:
            raise FileFormatError(f"annotation topic {topic!r} is not in this bag; topics: "
                                  f"{sorted({c.topic for c in reader.connections})}",
                                  path=path, trial=trial,
                                  hint="set annotation_topic in the trial sheet")
        if hits[0].msgtype not in PERSON_TYPES:
            raise FileFormatError(f"annotation topic {topic!r} holds {hits[0].msgtype}, not "
                                  f"one of {', '.join(PERSON_TYPES)}", path=path, trial=trial)
        return hits
    topics = sorted({c.topic for c in cands})
    if len(topics) != 1:
        raise FileFormatError(f"{'no' if not topics else 'several'} annotation topic(s) of "
                              f"type {', '.join(PERSON_TYPES)} in this bag"
                              f"{': ' + str(topics) if topics else ''}", path=path,
                              trial=trial, hint="set annotation_topic in the trial sheet")
    return [c for c in cands if c.topic == topics[0]]


def _marker_frame(reader, topic: str) -> str:
    """The frame of the annotation tool's display markers of ``topic`` ('' if none)."""
    ns = _norm(topic) + "_markers"
    conns = [c for c in reader.connections if c.msgtype == MARKER]
    for con, _, raw in reader.messages(connections=conns):
        m = reader.deserialize(raw, con.msgtype)
        if m.ns == ns and m.header.frame_id:
            return str(m.header.frame_id)
    return ""


@loader("ROS bag")
def read_bag_annotations(path: str | Path, topic: str | None = None,
                         scan_topic: str | None = None, *, trial: str | None = None
                         ) -> tuple[pd.DataFrame, dict[str, Any]]:
    """Annotated person positions of a bag, each assigned to its scan (module notes).

    Parameters
    ----------
    path : ROS 1 bag or ROS 2 bag folder.
    topic : annotation topic (``None``: the only one of a type in :data:`PERSON_TYPES`).
    scan_topic : the LaserScan topic tracked (``None``: the only one).
    trial : trial id, named in errors.

    Returns
    -------
    positions : DataFrame
        :data:`POSITION_COLUMNS`: ``k`` scan index (bag order of ``scan_topic``), ``t_s``
        that scan's header stamp (s), ``x_m``, ``y_m`` (laser frame, m), ``id`` (str),
        ``frame``; sorted by ``k`` then ``id``.
    meta : dict
        ``topic``, ``msgtype``, ``scan_topic``, ``frame``, ``frame_source``,
        ``n_messages``, ``n_before_first_scan`` (annotations older than every scan,
        dropped), ``ids``.

    Raises
    ------
    FileFormatError
        No or several annotation topics, a frame other than the scan's, non-finite
        positions, or no annotation at all.
    """
    path = Path(path)
    reader = _open(path, trial)
    try:
        _register_custom_types(reader)
        chosen = _pick_topic(reader, scan_topic, path, trial)
        conns = _pick_annotation_topic(reader, topic, path, trial)
        ann_topic, msgtype = conns[0].topic, conns[0].msgtype
        scan_conns = [c for c in reader.connections
                      if c.topic == chosen and c.msgtype == LASERSCAN]
        recv, stamps, scan_frames = [], [], set()
        for con, ts, raw in reader.messages(connections=scan_conns):
            m = reader.deserialize(raw, con.msgtype)
            recv.append(int(ts))
            stamps.append(int(m.header.stamp.sec) * 1_000_000_000 + int(m.header.stamp.nanosec))
            scan_frames.add(str(m.header.frame_id))
        rows, frames = [], set()
        for con, ts, raw in reader.messages(connections=conns):
            people, frame = _persons(reader.deserialize(raw, con.msgtype), msgtype)
            frames.add(frame)
            rows += [(int(ts), pid, x, y) for pid, x, y in people]
        marker_frame = _marker_frame(reader, ann_topic) if msgtype == PERSON_TYPES[0] else ""
    finally:
        reader.close()
    if not rows:
        raise FileFormatError(f"annotation topic {ann_topic} holds no annotated person",
                              path=path, trial=trial)
    scan_frame = ",".join(sorted(scan_frames))
    frames.discard("")
    if marker_frame:
        frame, source = marker_frame, f"{_norm(ann_topic)}_markers display markers"
    elif frames:
        frame, source = ",".join(sorted(frames)), "message header"
    else:
        frame, source = scan_frame, "assumed: the scan's frame (no header, no markers)"
    if frame != scan_frame:
        raise FileFormatError(f"annotations on {ann_topic} are in frame {frame!r} ({source}) "
                              f"but the scans on {chosen} in {scan_frame!r}; gaitval does "
                              "not transform between frames", path=path, trial=trial,
                              hint="export the annotations in the laser frame")
    a = pd.DataFrame(rows, columns=["t_bag_ns", "id", "x_m", "y_m"])
    bad = ~np.isfinite(a[["x_m", "y_m"]].to_numpy()).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise FileFormatError(f"annotation {i} on {ann_topic} has a non-finite position",
                              path=path, trial=trial)
    recv_ns = np.asarray(recv, dtype=np.int64)
    if np.any(np.diff(recv_ns) < 0):
        raise FileFormatError(f"scans on {chosen} are not in bag-time order", path=path,
                              trial=trial)
    # the last scan received before each annotation (benchmark convention, module notes)
    k = np.searchsorted(recv_ns, a["t_bag_ns"].to_numpy(dtype=np.int64), side="left") - 1
    keep = k >= 0
    a = a[keep].assign(k=k[keep])
    stamps_ns = np.asarray(stamps, dtype=np.int64)
    if np.all(stamps_ns == 0):                       # as read_rosbag_scans: receive time
        stamps_ns = recv_ns
    st = stamps_ns[a["k"].to_numpy()]
    a["t_s"] = (st // 1_000_000_000).astype(np.float64) + (st % 1_000_000_000) * 1e-9
    a["frame"] = frame
    out = (a.sort_values(["k", "id"], kind="stable")[POSITION_COLUMNS]
           .reset_index(drop=True))
    meta = {"topic": ann_topic, "msgtype": msgtype, "scan_topic": chosen, "frame": frame,
            "frame_source": source, "n_messages": int(len(rows)),
            "n_before_first_scan": int((~keep).sum()),
            "ids": sorted(out["id"].unique().tolist())}
    return out, meta


def write_position_csv(path: str | Path, positions: pd.DataFrame) -> Path:
    """Write annotated positions (``t_s, x_m, y_m, id, frame``) as a position CSV."""
    body = positions[["t_s", "x_m", "y_m", "id", "frame"]].to_csv(
        index=False, lineterminator="\n", float_format="%.9g")
    return write_text(path, POSITIONS_MAGIC + "\n" + body)


@loader("position annotation file")
def read_position_csv(path: str | Path, *, trial: str | None = None) -> pd.DataFrame:
    """Read a position CSV (module notes); ``k`` is left empty (-1) for the evaluation to
    assign from the scan stamps (:func:`gaitval.evaluate.clearmot.assign_scans`)."""
    path = Path(path)
    if not path.is_file():
        raise FileFormatError("position annotation file not found", path=path, trial=trial)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"not UTF-8 text (position {exc.start})", path=path,
                              trial=trial) from None
    lines = text.splitlines()
    if not lines or lines[0].strip() != POSITIONS_MAGIC:
        raise FileFormatError(f"first line must be '{POSITIONS_MAGIC}'", path=path,
                              trial=trial, hint="see docs/formats_recordings.md")
    body = "\n".join(ln for ln in lines[1:] if not ln.startswith("#"))
    try:
        df = pd.read_csv(io.StringIO(body), dtype={"id": str, "frame": str},
                         keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise FileFormatError(f"cannot parse the position table: {exc}", path=path,
                              trial=trial) from None
    missing = [c for c in ("t_s", "x_m", "y_m", "id") if c not in df]
    if missing:
        raise FileFormatError(f"position table has no column(s) {missing}", path=path,
                              trial=trial, hint="columns t_s, x_m, y_m, id[, frame]")
    for c in ("t_s", "x_m", "y_m"):
        v = pd.to_numeric(df[c], errors="coerce").to_numpy(dtype=float, na_value=np.nan)
        bad = ~np.isfinite(v)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            raise FileFormatError(f"{c} is not a finite number on line {i + 3} "
                                  f"({df[c].iloc[i]!r})", path=path, trial=trial)
        df[c] = v
    if "frame" not in df:
        df["frame"] = ""
    df["k"] = -1
    return df[POSITION_COLUMNS].sort_values(["t_s", "id"], kind="stable").reset_index(drop=True)
