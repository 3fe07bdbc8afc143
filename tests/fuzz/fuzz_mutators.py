"""Mutants of every file kind gaitval reads, made deterministically from (kind, seed, index).

Seeds: the real C3D files and ROS bags in ``../shared/realdata/`` (read from there, never
copied into the repository) and small generated scan logs, ultrasonic logs, annotation
files and trial sheets.  Mutations: byte flips and runs of 0x00/0xFF/0x80, truncation,
zeroed and random chunks, inserted and deleted bytes; for C3D also the parameter section's
type, dimension and pointer bytes, the header's words (huge integers), the values of
numeric parameters (floats and integers set to 0, -1, 3e9, NaN, inf, 65535 ...) and text
bytes (Latin-1, control bytes); for ROS 1 bags also the bag header's ``chunk_count``,
``conn_count`` and ``index_pos``, the index records' ``conn`` and ``count`` and the chunk
infos' counts; for Parquet logs their JSON metadata (NaN, inf, huge integers, wrong types,
missing keys), columns (odd values, other types: bool, timestamp, integer, text) and
row counts (0, 1); for CSV files cells (NaN, inf, empty, 5,000 characters,
``../../etc/passwd``), encodings (UTF-16, Latin-1) and structure.  Each mutant is one
file (or a folder for a sheet) and a one-line description of what was done to it.
"""
from __future__ import annotations

import json
import struct
from pathlib import Path

import numpy as np

REALDATA = (Path(__file__).resolve().parents[2] / ".." / "shared" / "realdata").resolve()
#: Intel and DEC files, with and without prefixes, duplicates, events, analogs; the larger
#: walks (FunctionalWalk, opensim_walking2) add time, not new structure
C3D_SEEDS = ["Gait_MotionAnalysis.c3d", "c3dorg_sample01_Eb015pi.c3d",
             "PiG_Calibration-FlatFoot-Full.c3d", "c3dorg_sample09_PlugInC3D.c3d",
             "c3dorg_sample04_sub_labels.c3d"]
#: one topic, and three (the bag of the issue's chunk_count / connection id reproducers)
BAG_SEEDS = ["positive_1.bag", "negative_2.bag"]
ODD_VALUES = [float("nan"), float("inf"), float("-inf"), 0, -1, 1e308, 2 ** 70, -2 ** 63,
              "abc", "", [], {}, None, True, [1, 2], "1e999", "NaN"]
EXTREME_FLOATS = [0.0, -1.0, 3e9, -3e9, 1e38, 1e-30, float("nan"), float("inf"),
                  float("-inf"), 100_001.0, 0.5, 65536.0]
EXTREME_INTS = [0, -1, 1, 2, 32767, -32768, 65535, 255, 127]
ODD_CELLS = ["nan", "inf", "-inf", "", "1e999", "-1", "0", "x" * 5000, "../../etc/passwd",
             "/etc/passwd", "é", "\x00", "1,5", '"', "true", "99999999999999999999"]


def byte_mutation(data: bytes, rng: np.random.Generator) -> tuple[bytes, str]:
    """One generic byte-level mutation."""
    b = bytearray(data)
    n = len(b)
    op = int(rng.integers(8))
    if op == 0:
        k = int(rng.integers(1, 9))
        for i in rng.integers(0, n, k):
            b[int(i)] = int(rng.integers(256))
        return bytes(b), f"{k} random bytes"
    if op == 1:
        i, v = int(rng.integers(n)), int(rng.choice([0x00, 0xFF, 0x80, 0x7F]))
        b[i] = v
        return bytes(b), f"byte {i} -> 0x{v:02X}"
    if op == 2:
        i = int(rng.integers(n))
        return bytes(b[:i]), f"first {i} bytes"
    if op in (3, 4):
        i, m = int(rng.integers(n)), int(rng.integers(1, 2048))
        b[i:i + m] = bytes(m) if op == 3 else rng.bytes(m)
        return bytes(b[:n]), f"{'zeroed' if op == 3 else 'random'} chunk {i}+{m}"
    if op == 5:
        i, m = int(rng.integers(n)), int(rng.integers(1, 64))
        return bytes(b[:i] + rng.bytes(m) + b[i:]), f"{m} bytes inserted at {i}"
    if op == 6:
        i, m = int(rng.integers(n)), int(rng.integers(1, 64))
        return bytes(b[:i] + b[i + m:]), f"{m} bytes deleted at {i}"
    i = int(rng.integers(max(n - 8, 1)))
    b[i:i + 4] = struct.pack("<i", int(rng.choice([2 ** 31 - 1, -2 ** 31, 65535, -1])))
    return bytes(b[:n]), f"huge int32 at {i}"


def _c3d_positions(data: bytes) -> dict[str, list[int]]:
    """Offsets of the parameter records' type/dimension/pointer bytes and header words."""
    pos = {"type": [], "dims": [], "ptr": [], "text": [], "value": [],
           "header": [2, 4, 6, 8, 12, 16, 18, 20]}
    i = (max(data[0], 1) - 1) * 512 + 4
    for _ in range(5000):
        if i + 2 > len(data):
            break
        nch, gid = struct.unpack_from("<bb", data, i)
        if nch == 0 or gid == 0:
            break
        p = i + 2 + abs(nch)
        nxt = struct.unpack_from("<h", data, p)[0] if p + 2 <= len(data) else 0
        pos["ptr"].append(p)
        if gid > 0 and p + 4 <= len(data):
            pos["type"].append(p + 2)
            pos["dims"].append(p + 3)
            if data[p + 2] == 0xFF:
                pos["text"].append(p + 4 + data[p + 3])
            elif data[p + 2] in (1, 2, 4) and data[p + 3] < 8:
                d0 = p + 4 + data[p + 3]                     # the first value
                if d0 + data[p + 2] <= len(data):
                    pos["value"].append(d0 * 8 + data[p + 2])   # offset and type in one
        if nxt <= 0:
            break
        i = p + nxt
    return pos


def c3d_mutation(data: bytes, rng: np.random.Generator) -> tuple[bytes, str]:
    """A structure-aware C3D mutation half the time, a generic one otherwise."""
    if rng.random() < 0.5:
        return byte_mutation(data, rng)
    pos = _c3d_positions(data)
    field = str(rng.choice([k for k, v in pos.items() if v]))
    i = int(rng.choice(pos[field]))
    b = bytearray(data)
    if field in ("ptr", "header"):
        v = int(rng.choice([0, 1, -1, 32767, -32768, 0x7FFF, 4, 600, 65535]))
        b[i:i + 2] = struct.pack("<H", v & 0xFFFF)
    elif field == "value":                  # a numeric parameter's first value
        i, typ = divmod(i, 8)
        if typ == 4:
            v = EXTREME_FLOATS[int(rng.integers(len(EXTREME_FLOATS)))]
            b[i:i + 4] = struct.pack("<f", v)
        elif typ == 2:
            v = EXTREME_INTS[int(rng.integers(len(EXTREME_INTS)))]
            b[i:i + 2] = struct.pack("<H", v & 0xFFFF)
        else:
            v = EXTREME_INTS[int(rng.integers(len(EXTREME_INTS)))]
            b[i] = v & 0xFF
        return bytes(b), f"c3d parameter value ({'float' if typ == 4 else 'int'}) at {i} " \
                         f"-> {v!r}"
    elif field == "text":
        v = int(rng.choice([0xFF, 0x80, 0xC3, 0x01, 0x00, 0xB2, 0xE9]))
        b[min(i + int(rng.integers(0, 4)), len(b) - 1)] = v
    else:
        v = int(rng.choice([0xFF, 0x00, 0x03, 0x7F, 0x80, 0x04, 0x02, 0x01, 0x09]))
        b[i] = v
    return bytes(b), f"c3d {field} at {i} -> {v}"


def _bag_fields(data: bytes) -> list[tuple[int, str]]:
    """(offset of the 4-byte value, field name) of the record fields a ROS 1 bag's index
    rests on: the bag header's ``chunk_count``/``conn_count``/``index_pos`` and every
    ``conn=``/``count=`` (index records, connections, chunk infos); and the chunk infos'
    (connection, count) pairs, as ``info``."""
    out = []
    for name in (b"chunk_count=", b"conn_count=", b"index_pos=", b"conn=", b"count="):
        i = data.find(name)
        while i >= 0 and len(out) < 4000:
            if i + len(name) + 4 <= len(data):
                out.append((i + len(name), name.decode().rstrip("=")))
            i = data.find(name, i + 1)
    pos = 13                                     # chunk infos: walk the records
    while pos + 8 <= len(data) and len(out) < 5000:
        hlen = struct.unpack_from("<I", data, pos)[0]
        if pos + 8 + hlen > len(data):
            break
        dlen = struct.unpack_from("<I", data, pos + 4 + hlen)[0]
        if b"op=\x06" in data[pos + 4:pos + 4 + hlen]:
            for k in range(min(dlen // 8, 16)):        # (conn, count) pairs
                out += [(pos + 8 + hlen + 8 * k, "info conn"),
                        (pos + 8 + hlen + 8 * k + 4, "info count")]
        pos += 8 + hlen + dlen
    return out


def bag_mutation(data: bytes, rng: np.random.Generator) -> tuple[bytes, str]:
    """An index-aware ROS bag mutation half the time, a generic one otherwise."""
    fields = _bag_fields(data) if rng.random() < 0.5 else []
    if not fields:
        return byte_mutation(data, rng)
    names = sorted({n for _, n in fields})            # each kind of field equally often
    name = names[int(rng.integers(len(names)))]
    at = [a for a, n in fields if n == name][int(rng.integers(
        sum(n == name for _, n in fields)))]
    old = struct.unpack_from("<I", data, at)[0]
    v = int(rng.choice([0, 1, 2, 7, 0xFFFFFFFF, old + 1, max(old - 1, 0), old // 2,
                        old * 2]))
    b = bytearray(data)
    struct.pack_into("<I", b, at, v & 0xFFFFFFFF)
    return bytes(b), f"bag field {name} at {at}: {old} -> {v & 0xFFFFFFFF}"


def _write_parquet(path: Path, cols: dict, key: bytes, meta) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    table = pa.table(cols)
    raw = meta if isinstance(meta, bytes) else json.dumps(meta).encode()
    pq.write_table(table.replace_schema_metadata({key: raw}), path)


def parquet_mutation(kind: str, path: Path, rng: np.random.Generator) -> str:
    """Write a scan log or ultrasonic log with mutated metadata, columns or bytes."""
    import pyarrow as pa

    import fuzz_seeds
    cols, key, meta = fuzz_seeds.parquet_parts(kind)
    op = int(rng.integers(6))
    what = "valid"
    if op == 0:                                           # a metadata value
        k = str(rng.choice(sorted(meta)))
        meta[k] = ODD_VALUES[int(rng.integers(len(ODD_VALUES)))]
        what = f"meta {k} = {meta[k]!r}"[:80]
    elif op == 1:                                         # a metadata key dropped / junk JSON
        if rng.random() < 0.5:
            k = str(rng.choice(sorted(meta)))
            del meta[k]
            what = f"meta {k} missing"
        else:
            meta = rng.bytes(int(rng.integers(1, 40)))
            what = "meta random bytes"
    elif op == 2:                                         # a column
        c = str(rng.choice(sorted(cols)))
        v = ODD_VALUES[int(rng.integers(3))]
        n = len(cols["t_s"])
        choice = int(rng.integers(3))
        if choice == 0 and c != "ranges":
            arr = np.asarray(cols[c], dtype=float).copy()
            arr[int(rng.integers(n))] = v
            cols[c] = arr
        elif choice == 1:
            cols[c] = pa.array(["x"] * n)
        else:
            cols.pop(c)
        what = f"column {c} #{choice}"
    elif op == 4:                                         # a column of another type
        c = str(rng.choice(sorted(cols)))
        n = len(cols["t_s"])
        how = str(rng.choice(["bool", "timestamp", "int64", "float32", "string", "date"]))
        base = np.asarray(cols[c]) if c != "ranges" else np.arange(n, dtype=float)
        if how == "bool":
            cols[c] = pa.array(np.ones(n, dtype=bool))
        elif how == "timestamp":
            cols[c] = pa.array((np.asarray(base, dtype=float) * 1e9).astype("datetime64[ns]"))
        elif how == "int64":
            cols[c] = pa.array(np.asarray(base, dtype=float).astype(np.int64))
        elif how == "float32":
            cols[c] = pa.array(np.asarray(base, dtype=np.float32))
        elif how == "date":
            cols[c] = pa.array(np.zeros(n, dtype="datetime64[D]"))
        else:
            cols[c] = pa.array([str(x) for x in np.asarray(base, dtype=float)])
        what = f"column {c} as {how}"
    elif op == 5:                                         # 0 or 1 rows (no rate)
        k = int(rng.integers(2))
        table = pa.table(cols).slice(0, k)
        cols = {c: table[c] for c in table.column_names}
        what = f"{k} rows"
    _write_parquet(path, cols, key, meta)
    if op == 3:
        data, what = byte_mutation(path.read_bytes(), rng)
        path.write_bytes(data)
    return f"{kind}: {what}"


#: Ids that must never name a trial's folder or reach a shell word (issue 33).
SPECIAL_IDS = [".", "..", "a b", "x$(id>PWNED)", "`id`", "a;b", "t" * 5000, "a/b", "-rf",
               "../x", "a\tb", "é", "a'b", 'a"b', "*", "~", "a|b", "$HOME"]


def sheet_id_mutation(text: str, rng: np.random.Generator) -> tuple[bytes, str]:
    """Set the study, subject or trial cell of one row of a trial sheet to a special id."""
    lines = text.splitlines()
    i = int(rng.integers(1, len(lines)))
    col = int(rng.choice([0, 2, 3]))                      # study, subject, trial
    parts = lines[i].split(",")
    special = SPECIAL_IDS[int(rng.integers(len(SPECIAL_IDS)))]
    parts[col] = '"' + special.replace('"', '""') + '"'
    lines[i] = ",".join(parts)
    return ("\n".join(lines) + "\n").encode(), f"line {i} id column {col} = {special[:20]!r}"


def text_mutation(text: str, rng: np.random.Generator, cells: bool = True
                  ) -> tuple[bytes, str]:
    """Mutate a CSV text: a cell, a line, or its encoding."""
    lines = text.splitlines()
    op = int(rng.integers(5 if cells else 4))
    if op == 0:
        return text.encode("utf-16"), "UTF-16"
    if op == 1:
        return text.encode("utf-8") + b"\xff\xfe\xe9", "non-UTF-8 bytes"
    if op == 2 and len(lines) > 1:
        i = int(rng.integers(len(lines)))
        lines.insert(i, lines[i] if rng.random() < 0.5 else ",,,,")
        return "\n".join(lines).encode(), f"line {i} doubled or blank"
    if op == 3:
        i = int(rng.integers(len(lines)))
        del lines[i]
        return "\n".join(lines).encode(), f"line {i} deleted"
    i = int(rng.integers(len(lines)))
    parts = lines[i].split(",")
    j = int(rng.integers(len(parts)))
    parts[j] = ODD_CELLS[int(rng.integers(len(ODD_CELLS)))]
    lines[i] = ",".join(parts)
    return "\n".join(lines).encode("utf-8", "surrogatepass"), \
        f"line {i} cell {j} = {parts[j][:20]!r}"


#: Mutations whose file is readable but says something implausible: the loader must refuse
#: it or warn (a quiet load is the failure ``implausible``).  Each description starts
#: with IMPLAUSIBLE.
IMPLAUSIBLE = "implausible"


def c3d_implausible(src: Path, out: Path, rng: np.random.Generator) -> str:
    """A real C3D with its declared unit or its scale made wrong (ezc3d rewrites it)."""
    import ezc3d

    how = str(rng.choice(["units m", "units cm", "units blank", "km"]))
    for path in (src, REALDATA / "c3d" / "opensim_walking2.c3d"):
        c = ezc3d.c3d(str(path))
        if how.startswith("units"):
            unit = {"units m": "m", "units cm": "cm", "units blank": ""}[how]
            c["parameters"]["POINT"]["UNITS"]["value"] = [unit]
        else:                   # every coordinate x 1e6 with mm declared: kilometres
            pts = c["data"]["points"]
            pts[:3] *= 1e6
            c["data"]["points"] = pts
        try:
            c.write(str(out))
            break
        except (ValueError, RuntimeError):  # ezc3d cannot write this seed back (LABELS2)
            continue
    return f"{IMPLAUSIBLE} {how}" + ("" if path == src else f" (of {path.name})")


def parquet_implausible(kind: str, path: Path, rng: np.random.Generator) -> str:
    """A scan log whose ranges are all negative or all beyond its limits (metres written
    as mm...), or an ultrasonic log stamped in whole seconds."""
    import pyarrow as pa

    import fuzz_seeds
    cols, key, meta = fuzz_seeds.parquet_parts(kind)
    if kind == "scanlog":
        nb = int(meta["n_beams"])
        ranges = np.asarray(cols["ranges"].flatten(), dtype=np.float32)
        how = str(rng.choice(["negative", "x1000"]))
        ranges = -ranges if how == "negative" else ranges * 1000.0
        cols["ranges"] = pa.FixedSizeListArray.from_arrays(pa.array(ranges), nb)
    else:
        how = "whole-second stamps"
        cols["t_s"] = np.floor(np.asarray(cols["t_s"], dtype=float))
    _write_parquet(path, cols, key, meta)
    return f"{kind}: {IMPLAUSIBLE} {how}"
