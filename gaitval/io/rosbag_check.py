"""The record structure of a ROS 1 bag, walked in pure Python to check what a reader got.

Part of :mod:`gaitval.io.rosbag`.  ``rosbags`` [1]_ trusts a bag's index: it reads the
``chunk_count`` chunk infos the bag header announces, then the messages the index records
list.  A bag whose ``chunk_count`` is 1 (of 6) therefore loaded 82 of 435 scans per topic
without a word, and a corrupted connection id in an index record moved a topic's messages
elsewhere.  :func:`walk_bag1` walks the file's top-level records (bag header, chunks, the
index data after each chunk, connections and chunk infos of the index section) without
decompressing anything; :func:`check_structure` compares the counts found with each
other (whenever a bag is opened) and :func:`check_counts` also with the messages the
reader delivered for a topic.

ROS bag format 2.0 [2]_: after the line ``#ROSBAG V2.0``, records ``header_len (uint32),
header (fields: field_len (uint32), name=value), data_len (uint32), data``; the header's
``op`` field says the kind: 0x03 bag header (``index_pos``, ``conn_count``,
``chunk_count``), 0x05 chunk, 0x04 index data (``conn``, ``count``), 0x07 connection
(``conn``), 0x06 chunk info (data: ``count`` pairs of (conn, message count)).

References
----------
.. [1] Ternig, M. et al. rosbags: pure Python library to read, modify, convert and write
   rosbag files. https://gitlab.com/ternaris/rosbags
.. [2] ROS Bag Format 2.0. http://wiki.ros.org/Bags/Format/2.0
"""
from __future__ import annotations

import struct
from pathlib import Path
from typing import Any

from gaitval.errors import FileFormatError

MAGIC = b"#ROSBAG V2.0\n"
_OP_BAG, _OP_INDEX, _OP_CHUNK, _OP_INFO, _OP_CONN = 0x03, 0x04, 0x05, 0x06, 0x07


class BagStructureError(Exception):
    """The record structure is broken (the message names the byte offset)."""


def _fields(header: bytes, at: int) -> dict[str, bytes]:
    out, i = {}, 0
    while i < len(header):
        if i + 4 > len(header):
            raise BagStructureError(f"the record header at byte {at} is cut off")
        n = struct.unpack_from("<I", header, i)[0]
        field = header[i + 4:i + 4 + n]
        if len(field) < n or b"=" not in field:
            raise BagStructureError(f"the record header at byte {at} holds a broken field")
        name, _, value = field.partition(b"=")
        out[name.decode("latin-1")] = value
        i += 4 + n
    return out


def _u32(fields: dict[str, bytes], key: str, at: int) -> int:
    v = fields.get(key)
    if v is None or len(v) != 4:
        raise BagStructureError(f"the record at byte {at} has no 4-byte '{key}' field")
    return struct.unpack("<I", v)[0]


def walk_bag1(path: Path) -> dict[str, Any]:
    """Counts of a ROS 1 bag's top-level records.

    Returns
    -------
    dict
        ``chunk_count`` and ``conn_count`` (as the bag header announces them), ``chunks``
        (chunk records found), ``chunk_infos`` (chunk-info records found),
        ``connections`` (ids defined in the index section), ``index_counts`` (connection
        -> messages listed by the index records after the chunks), ``info_counts``
        (connection -> messages listed by the chunk infos).

    Raises
    ------
    BagStructureError
        A record that overruns the file, has no ``op`` field or a malformed field.
    """
    size = path.stat().st_size
    out: dict[str, Any] = {"chunk_count": None, "conn_count": None, "chunks": 0,
                           "chunk_infos": 0, "connections": set(), "index_counts": {},
                           "info_counts": {}}
    with open(path, "rb") as fh:
        if fh.read(len(MAGIC)) != MAGIC:
            raise BagStructureError("the file does not start with '#ROSBAG V2.0'")
        pos = len(MAGIC)
        while pos < size:
            fh.seek(pos)
            raw = fh.read(4)
            if len(raw) < 4:
                raise BagStructureError(f"the record at byte {pos} is cut off")
            hlen = struct.unpack("<I", raw)[0]
            if pos + 8 + hlen > size:
                raise BagStructureError(f"the record at byte {pos} announces a "
                                        f"{hlen}-byte header beyond the end of the file")
            header = fh.read(hlen)
            dlen = struct.unpack("<I", fh.read(4))[0]
            if pos + 8 + hlen + dlen > size:
                raise BagStructureError(f"the record at byte {pos} announces {dlen} bytes "
                                        "of data beyond the end of the file")
            f = _fields(header, pos)
            op = f.get("op")
            if op is None or len(op) != 1:
                raise BagStructureError(f"the record at byte {pos} has no 'op' field "
                                        "(zeroed or overwritten bytes)")
            op = op[0]
            if op == _OP_BAG:
                out["chunk_count"] = _u32(f, "chunk_count", pos)
                out["conn_count"] = _u32(f, "conn_count", pos)
            elif op == _OP_CHUNK:
                out["chunks"] += 1
            elif op == _OP_INDEX:
                conn = _u32(f, "conn", pos)
                out["index_counts"][conn] = (out["index_counts"].get(conn, 0)
                                             + _u32(f, "count", pos))
            elif op == _OP_CONN:
                out["connections"].add(_u32(f, "conn", pos))
            elif op == _OP_INFO:
                out["chunk_infos"] += 1
                n = _u32(f, "count", pos)
                if 8 * n > dlen:
                    raise BagStructureError(f"the chunk info at byte {pos} lists {n} "
                                            f"connections in {dlen} bytes")
                data = fh.read(8 * n)
                for k in range(n):
                    conn, count = struct.unpack_from("<II", data, 8 * k)
                    out["info_counts"][conn] = out["info_counts"].get(conn, 0) + count
            pos += 8 + hlen + dlen
    return out


def _refuse(path: Path, trial: str | None, problem: str):
    raise FileFormatError(f"the bag's index disagrees with its contents: {problem}",
                          path=path, trial=trial,
                          hint="reindex it (`rosbag reindex`) or re-record it")


def check_structure(path: Path, trial: str | None) -> dict[str, Any]:
    """:func:`walk_bag1`, and the counts of the whole bag checked against each other; the
    walk's result.

    Raises
    ------
    FileFormatError
        A broken record; chunk records, chunk infos and the header's ``chunk_count`` that
        disagree; connection records and ``conn_count`` that disagree; index records or
        chunk infos naming an undefined connection.  (A ``chunk_count`` of 0 used to give
        a bag without topics, and 1 a bag of 82 of 435 scans per topic.)
    """
    try:
        s = walk_bag1(path)
    except (BagStructureError, OSError, struct.error) as exc:
        raise FileFormatError(f"the bag's record structure is broken: {exc}", path=path,
                              trial=trial, hint="`rosbag reindex` may repair it") from None
    if s["chunk_count"] is None:
        _refuse(path, trial, "it has no bag header record")
    if not s["chunk_count"] == s["chunks"] == s["chunk_infos"]:
        _refuse(path, trial, f"the bag header announces chunk_count={s['chunk_count']}, "
                             f"the file holds {s['chunks']} chunk records and "
                             f"{s['chunk_infos']} chunk infos")
    if s["conn_count"] != len(s["connections"]):
        _refuse(path, trial, f"the bag header announces conn_count={s['conn_count']}, the "
                             f"index section defines {len(s['connections'])} connections")
    for where in ("index_counts", "info_counts"):
        stray = sorted(set(s[where]) - s["connections"])
        if stray:
            _refuse(path, trial,
                    f"the {'index records' if where == 'index_counts' else 'chunk infos'} "
                    f"list messages of connection(s) {stray}, which the bag does not define "
                    f"(defined: {sorted(s['connections'])})")
    return s


def check_counts(path: Path, trial: str | None, topic: str, read: dict[int, int],
                 topic_conns: list[int]) -> None:
    """:func:`check_structure`, then for each connection of ``topic`` the messages listed
    by the index records and by the chunk infos against those read (``read``: connection
    id -> messages delivered)."""
    s = check_structure(path, trial)
    for conn in topic_conns:
        idx, info, got = (s["index_counts"].get(conn, 0), s["info_counts"].get(conn, 0),
                          read.get(conn, 0))
        if not idx == info == got:
            _refuse(path, trial, f"topic {topic} (connection {conn}): the index records "
                                 f"list {idx} messages, the chunk infos {info}, and {got} "
                                 "were read")
