"""The exchange format's header and columns (docs/formats_external.md, *Leg tracks*), shared by leg
tracks, leg detections (:mod:`gaitval.io.tracks.detections`) and heel trajectories
(:mod:`gaitval.io.foot`): the header checked, the columns read from CSV or Parquet and
parsed, each problem naming the file, the field or column and the row.
"""
from __future__ import annotations

import csv
import io
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError


FORMAT = "gaitval-tracks"
VERSION = 1
META_KEY = b"gaitval:tracks"
UNITS = {"m": 1.0, "mm": 1e-3}
FRAMES = ("sensor", "mocap")
CLOCKS = ("sensor", "mocap")
SIDES = ("L", "R")
#: leg patterns of seed 001 §2.3 (gaitval.detect.legpatterns); empty: no track yet
PATTERNS = ("", "SL", "LT", "FS_O", "FS_U", "UO")
#: the columns of the exchange format, in file order (required: t_s, x, y, and side or
#: person)
COLUMNS = ("t_s", "k", "side", "person", "x", "y", "vx", "vy", "observed", "pattern",
           "phase", "swing", "interpolated")
BOOL_COLUMNS = ("observed", "swing", "interpolated")
#: gaitval's own per-scan track columns (gaitval.track.leg.TrackResult.to_frame)
TRACK_COLUMNS = ("k", "t_sensor_s", "side", "x_m", "y_m", "vx_mps", "vy_mps", "observed",
                 "pattern", "phase", "swing", "interpolated")


_TRUE = {"true", "1", "yes"}
_FALSE = {"false", "0", "no"}


def _err(path, problem: str, trial=None, hint=None) -> FileFormatError:
    return FileFormatError(problem, path=path, trial=trial, hint=hint)


def _check_meta(meta: dict, path, trial, lines: dict | None = None, *, fmt: str = FORMAT,
                meta_key: bytes = META_KEY) -> dict:
    """The header, checked: format, version, units, frame, clock (each named when wrong,
    with its line of a CSV: ``lines``, key -> line number, and ``lines[None]`` the last
    header line; else the Parquet schema metadata)."""
    def at(key):
        if lines is None:
            return f" (schema metadata {meta_key.decode()!r})"
        if key in lines:
            return f" (line {lines[key]})"
        return f" (no '# {key}: ...' line among header lines 1-{lines.get(None, 1)})"

    if meta.get("format") != fmt:
        raise _err(path, f"header field 'format' is {meta.get('format')!r}, not {fmt!r}",
                   trial, hint=f"the first line of a CSV is '# {fmt} v{VERSION}'")
    v = meta.get("version")
    try:
        ok = float(v) == VERSION
    except (TypeError, ValueError):
        ok = False
    if not ok:
        raise _err(path, f"header field 'version' is {v!r}{at('version')}; this gaitval "
                   f"reads version {VERSION}", trial)
    for key, allowed in (("units", tuple(UNITS)), ("frame", FRAMES), ("clock", CLOCKS)):
        val = meta.get(key)
        if val is None:
            raise _err(path, f"header field {key!r} is missing{at(key)}; give one of "
                       f"{', '.join(allowed)}", trial)
        if val not in allowed:
            raise _err(path, f"header field {key!r} is {val!r}{at(key)}, not one of "
                       f"{', '.join(allowed)}", trial)
    out = dict(meta)
    out["version"] = VERSION
    if meta.get("clock_offset_s") not in (None, ""):
        # a tracker stamped on a third clock (its own computer's): the user states the
        # offset to the header's clock, t = t_s + clock_offset_s (docs/formats.md, Clock)
        raw = meta["clock_offset_s"]
        try:
            off = float(raw) if not isinstance(raw, bool) else float("nan")
        except (TypeError, ValueError):
            off = float("nan")
        if not math.isfinite(off):
            raise _err(path, f"header field 'clock_offset_s' is {raw!r}{at('clock_offset_s')}"
                       ", not a finite number of seconds", trial,
                       hint="seconds added to every t_s to put it on the header's clock")
        out["clock_offset_s"] = off
    return out


def _on_header_clock(t: np.ndarray, meta: dict) -> np.ndarray:
    """Time stamps as stored, moved onto the header's ``clock`` by its optional
    ``clock_offset_s`` (a third clock's offset, stated by the user)."""
    off = float(meta.get("clock_offset_s") or 0.0)
    return t + off if off else t


def _read_csv(path: Path, trial, fmt: str = FORMAT
              ) -> tuple[dict, list[str], list[list[str]], int, dict]:
    """(header, column names, rows as text, file line of the first data row, header
    key -> its line)."""
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise _err(path, f"not UTF-8 text ({exc.reason} at byte {exc.start})", trial) from None
    lines = text.splitlines()
    if not lines or lines[0].strip().lower() != f"# {fmt} v{VERSION}":
        first = lines[0][:60] if lines else ""
        raise _err(path, f"line 1 is {first!r}, not '# {fmt} v{VERSION}'", trial)
    meta: dict = {"format": fmt, "version": VERSION}
    where = {"format": 1, "version": 1}
    n = 1
    while n < len(lines) and lines[n].startswith("#"):
        key, sep, val = lines[n][1:].partition(":")
        if sep:
            meta[key.strip()] = val.strip()
            where[key.strip()] = n + 1
        n += 1
    where[None] = n
    rows = list(csv.reader(io.StringIO("\n".join(lines[n:]))))
    if not rows:
        raise _err(path, "no column header after the '#' lines", trial)
    return meta, [c.strip() for c in rows[0]], rows[1:], n + 2, where


def _columns_of(p: Path, trial, kind: str, fmt: str = FORMAT, meta_key: bytes = META_KEY):
    """A track or detections file (``kind``: ``tracks``/``detections``) as
    ``(meta, column names, {name: values}, where(i) -> "line N"/"row N", meta_lines,
    first data line)``: CSV cells checked against the header, Parquet rows 1-based."""
    if not p.exists():
        raise _err(p, "no such file", trial)
    if p.suffix == ".csv":
        meta, names, rows_txt, first_line, meta_lines = _read_csv(p, trial, fmt)
        for j, r in enumerate(rows_txt):
            if len(r) != len(names):
                raise _err(p, f"line {first_line + j}: {len(r)} cells, the header has "
                           f"{len(names)}", trial)
        cols = {n: [r[i] for r in rows_txt] for i, n in enumerate(names)}

        def where(i):
            return f"line {first_line + i}"
    elif p.suffix == ".parquet":
        meta, df = _read_parquet(p, trial, fmt, meta_key)
        meta_lines, first_line = None, 1
        names = list(df.columns)
        cols = {n: df[n].tolist() for n in names}

        def where(i):
            return f"row {i + 1}"
    else:
        raise _err(p, f"unknown extension {p.suffix!r}", trial,
                   hint=f"a {kind} file is *.{kind}.csv or *.{kind}.parquet")
    return meta, names, cols, where, meta_lines, first_line


def open_exchange(p: Path, trial, kind: str, fmt: str, meta_key: bytes, allowed,
                  required, why: str):
    """A detections or foot file (``kind``) opened and its header checked: as
    :func:`_columns_of`, after refusing a column not in ``allowed`` (``why`` says what
    the columns are for), a missing one of ``required``, and a file without rows."""
    meta, names, cols, where, meta_lines, first_line = _columns_of(p, trial, kind, fmt,
                                                                   meta_key)
    meta = _check_meta(meta, p, trial, meta_lines, fmt=fmt, meta_key=meta_key)
    unknown = [n for n in names if n not in allowed]
    if unknown:
        raise _err(p, f"unknown column(s) {', '.join(map(repr, unknown))}", trial,
                   hint=f"the columns are {', '.join(allowed)} ({why})")
    for c in required:
        if c not in names:
            raise _err(p, f"column {c!r} is missing", trial)
    if not cols[required[0]]:
        raise _err(p, "no rows", trial)
    return meta, names, cols, where, meta_lines, first_line


def _read_parquet(path: Path, trial, fmt: str = FORMAT, meta_key: bytes = META_KEY
                  ) -> tuple[dict, pd.DataFrame]:
    import pyarrow.parquet as pq
    try:
        tab = pq.read_table(path)
    except Exception as exc:                        # noqa: BLE001 - any unreadable file
        raise _err(path, f"not a readable Parquet file ({exc})", trial) from None
    raw = (tab.schema.metadata or {}).get(meta_key)
    if raw is None:
        raise _err(path, f"no schema metadata key {meta_key.decode()!r}: not a "
                   f"{fmt} file", trial)
    try:
        meta = json.loads(raw)
    except ValueError:
        raise _err(path, f"schema metadata {meta_key.decode()!r} is not JSON", trial) from None
    if not isinstance(meta, dict):
        raise _err(path, f"schema metadata {meta_key.decode()!r} is not a JSON object", trial)
    return meta, tab.to_pandas()


def _floats(path, col: str, values, rows, trial, finite: bool) -> np.ndarray:
    out = np.empty(len(values))
    for i, v in enumerate(values):
        if isinstance(v, str):
            v = v.strip()
            if v == "":
                v = "nan"
        if isinstance(v, (bool, np.bool_)):
            raise _err(path, f"column {col!r}, {rows(i)}: {v!r} is not a number", trial)
        try:
            out[i] = float(v)
        except (TypeError, ValueError):
            raise _err(path, f"column {col!r}, {rows(i)}: {v!r} is not a number",
                       trial) from None
        if finite and not math.isfinite(out[i]):
            raise _err(path, f"column {col!r}, {rows(i)}: {v!r} is not a finite number "
                       "(every row needs a time)", trial)
    return out


def _bools(path, col: str, values, rows, trial) -> np.ndarray:
    out = np.empty(len(values), bool)
    for i, v in enumerate(values):
        if isinstance(v, (bool, np.bool_)):
            out[i] = bool(v)
            continue
        s = str(v).strip().lower()
        if s in _TRUE:
            out[i] = True
        elif s in _FALSE:
            out[i] = False
        else:
            raise _err(path, f"column {col!r}, {rows(i)}: {v!r} is not true/false", trial)
    return out


def _ints(path, col: str, values, rows, trial, lo: int, hi: int) -> np.ndarray:
    f = _floats(path, col, values, rows, trial, finite=True)
    for i, v in enumerate(f):
        if v != int(v) or not lo <= v <= hi:
            raise _err(path, f"column {col!r}, {rows(i)}: {values[i]!r} is not a whole "
                       f"number from {lo} to {hi}", trial)
    return f.astype(np.int64)
