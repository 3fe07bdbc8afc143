"""Leg tracks as an exchange format: ``*.tracks.csv`` and ``*.tracks.parquet`` (version 1).

Any tracker's output — gaitval's own (``gaitval export-tracks``), a vendor's export, a
ROS node's topics converted — enters gaitval's tables through this one format
(issue 37; docs/formats.md, section *Leg tracks*).  One row per time stamp and leg
(``side`` ``L``/``R``) or, for a tracker that gives only people, per time stamp and
person (``person``).  Positions ``x``, ``y`` (velocities ``vx``, ``vy``) are in the
header's ``units`` (``m`` or ``mm``; per second for velocities) and ``frame`` (``sensor``:
the laser frame; ``mocap``: the field frame), times ``t_s`` in seconds on the header's
``clock`` (``sensor`` or ``mocap``).

:func:`read_tracks` returns the rows in metres with the header as a dict;
:func:`tracks_to_sensor` turns them into gaitval's per-scan track table
(:func:`gaitval.methods.track_trial`'s columns) on the sensor clock and in the sensor
frame, given the trial's registration; :func:`track_to_exchange` and
:func:`write_tracks` do the reverse for gaitval's own tracks, so that export and
re-import give back the same table, value for value.
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
from gaitval.io.atomic import write_bytes, write_parquet

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
#: seed 000 Table 2 speed thresholds: a track without ``swing`` is in swing from the scan
#: its speed exceeds v_sw_th until it falls below v_st_th (the tracker's hysteresis)
V_ST_TH, V_SW_TH = 0.47, 0.93
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


def read_tracks(path: str | Path, *, trial: str | None = None) -> tuple[pd.DataFrame, dict]:
    """Read a ``*.tracks.csv`` or ``*.tracks.parquet`` file.

    Returns
    -------
    (DataFrame, dict)
        The rows in file order, positions in metres (velocities m/s): ``t_s``, ``side``
        (``L``/``R``) or ``person``, ``x_m``, ``y_m`` and whichever of ``k``, ``vx_mps``,
        ``vy_mps``, ``observed``, ``pattern``, ``phase``, ``swing``, ``interpolated`` the
        file has; and the header (``format, version, units, frame, clock``, and any other
        key, e.g. ``source``).  Times are on the header's clock: as stored, plus the
        header's ``clock_offset_s`` when it gives one (a tracker on a third clock).

    Raises
    ------
    FileFormatError
        Naming the file, the field or column, and the row (CSV: the file's line;
        Parquet: the data row, 1-based): a wrong format line or version, units other than
        ``m``/``mm``, an unknown frame or clock, a missing column, a non-number, a side
        other than L/R, a leg missing at a time stamp, a time stamp given twice.
    """
    p = Path(path)
    meta, names, cols, where, meta_lines, first_line = _columns_of(p, trial, "tracks")
    meta = _check_meta(meta, p, trial, meta_lines)
    unknown = [n for n in names if n not in COLUMNS]
    if unknown:
        raise _err(p, f"unknown column(s) {', '.join(map(repr, unknown))}", trial,
                   hint=f"the columns are {', '.join(COLUMNS)}")
    for c in ("t_s", "x", "y"):
        if c not in names:
            raise _err(p, f"column {c!r} is missing", trial)
    if ("side" in names) == ("person" in names):
        raise _err(p, "exactly one of the columns 'side' (legs) and 'person' (people) "
                   "is needed", trial)
    n = len(cols["t_s"])
    if n == 0:
        raise _err(p, "no rows", trial)
    scale = UNITS[meta["units"]]
    out = {"t_s": _on_header_clock(_floats(p, "t_s", cols["t_s"], where, trial,
                                           finite=True), meta)}
    if "k" in names:
        out["k"] = _ints(p, "k", cols["k"], where, trial, 0, 2 ** 62)
    key = "side" if "side" in names else "person"
    ids = ["" if v is None else str(v).strip() for v in cols[key]]
    for i, v in enumerate(ids):
        if key == "side" and v not in SIDES:
            raise _err(p, f"column 'side', {where(i)}: {cols[key][i]!r} is not L or R",
                       trial)
        if key == "person" and not v:
            raise _err(p, f"column 'person', {where(i)}: empty person id", trial)
    out[key] = pd.Series(ids, dtype=object)
    for c, name in (("x", "x_m"), ("y", "y_m"), ("vx", "vx_mps"), ("vy", "vy_mps")):
        if c in names:
            v = _floats(p, c, cols[c], where, trial, finite=False)
            out[name] = v * scale if scale != 1.0 else v
    for c in BOOL_COLUMNS:
        if c in names:
            out[c] = _bools(p, c, cols[c], where, trial)
    if "pattern" in names:
        pat = ["" if v is None or (isinstance(v, float) and np.isnan(v)) else str(v).strip()
               for v in cols["pattern"]]
        for i, v in enumerate(pat):
            if v not in PATTERNS:
                raise _err(p, f"column 'pattern', {where(i)}: {v!r} is not one of "
                           f"{', '.join(x for x in PATTERNS if x)} or empty", trial)
        out["pattern"] = pd.Series(pat, dtype=object)
    if "phase" in names:
        out["phase"] = _ints(p, "phase", cols["phase"], where, trial, -1, 5)
    df = pd.DataFrame(out)
    dup = df.duplicated(["t_s", key])
    if dup.any():
        i = int(np.flatnonzero(dup.to_numpy())[0])
        raise _err(p, f"{where(i)}: time stamp {float(df['t_s'].iloc[i])!r} s has {key} "
                   f"{ids[i]!r} twice", trial)
    if key == "side":
        for s in SIDES:
            if not (df["side"] == s).any():
                raise _err(p, f"column 'side': leg {s} is missing (no row has side {s})",
                           trial, hint="a leg track file has rows for both legs; a tracker "
                           "that gives only people uses the column 'person'")
        counts = df.groupby("t_s", sort=False)["side"].transform("size")
        if (counts < 2).any():
            i = int(np.flatnonzero((counts < 2).to_numpy())[0])
            other = "R" if ids[i] == "L" else "L"
            raise _err(p, f"{where(i)}: leg {other} is missing at time stamp "
                       f"{float(df['t_s'].iloc[i])!r} s (every time stamp has one row per leg; "
                       "write x, y empty where a leg has no track)", trial)
    df.attrs = {}
    # where a row is in the file, for later errors (tracks_to_sensor): CSV lines or
    # Parquet data rows, in the order of the rows returned
    meta["_row"] = ("line", first_line) if meta_lines is not None else ("row", 1)
    return df, meta


# -- gaitval's own tracks ----------------------------------------------------------------
def track_to_exchange(track: pd.DataFrame) -> pd.DataFrame:
    """gaitval's per-scan track (sensor frame and clock, metres) as exchange-format rows."""
    out = pd.DataFrame({
        "t_s": track["t_sensor_s"].to_numpy(float), "k": track["k"].to_numpy(np.int64),
        "side": track["side"].astype(str).to_numpy(object),
        "x": track["x_m"].to_numpy(float), "y": track["y_m"].to_numpy(float)})
    for c, src in (("vx", "vx_mps"), ("vy", "vy_mps")):
        if src in track:
            out[c] = track[src].to_numpy(float)
    for c in ("observed", "pattern", "phase", "swing", "interpolated"):
        if c in track:
            out[c] = track[c].to_numpy()
    if "pattern" in out:
        out["pattern"] = out["pattern"].fillna("").astype(str)
    return out


def write_tracks(rows: pd.DataFrame, path: str | Path, *, units: str = "m",
                 frame: str = "sensor", clock: str = "sensor", **extra) -> Path:
    """Write exchange-format rows (columns of :data:`COLUMNS`; positions in ``units``)
    to ``*.tracks.csv`` or ``*.tracks.parquet``, atomically.  ``extra`` header keys (e.g.
    ``source``) are written after the required ones.  CSV floats are written with the
    shortest text that reads back to the same float (Python's ``repr``), so a round trip
    through CSV is exact."""
    p = Path(path)
    meta = _check_meta({"format": FORMAT, "version": VERSION, "units": units,
                        "frame": frame, "clock": clock}, p, None)
    meta.update({k: str(v) for k, v in extra.items()})
    rows = rows[[c for c in COLUMNS if c in rows.columns]].reset_index(drop=True)
    return _write_rows(p, rows, meta, FORMAT, META_KEY, "tracks", bool_columns=BOOL_COLUMNS)


def _check_registration(path, trial, frame: str, clock: str, reg: dict) -> None:
    """A file in the mocap frame or on the mocap clock needs the trial's registration's
    pose or clock offset: an error naming the file, the header field and what is unknown."""
    need = [f for f, v in (("frame", frame), ("clock", clock)) if v == "mocap"]
    if need:
        keys = (["x_m", "y_m", "yaw_rad"] if "frame" in need else []) + \
            (["clock_offset_s"] if "clock" in need else [])
        bad = [k for k in keys if reg.get(k) is None or not math.isfinite(float(reg[k]))]
        if bad:
            raise _err(path, f"header {' and '.join(need)} 'mocap' needs the trial's "
                       f"registration ({', '.join(bad)} unknown)", trial)


def _write_rows(p: Path, rows: pd.DataFrame, meta: dict, fmt: str, meta_key: bytes,
                kind: str, bool_columns=(), all_float: bool = False) -> Path:
    """A tracks or detections file (``kind``): Parquet with ``meta`` as JSON under
    ``meta_key``, or CSV after a ``# fmt vVERSION`` line and ``# key: value`` lines, booleans
    as ``true``/``false``, floats (every column with ``all_float``) as the shortest text
    that reads back to the same float, NaN as an empty cell."""
    if p.suffix == ".parquet":
        write_parquet(rows, p, metadata={meta_key.decode(): json.dumps(meta, sort_keys=True)})
        return p
    if p.suffix != ".csv":
        raise _err(p, f"unknown extension {p.suffix!r}", hint=f"*.{kind}.csv or "
                   f"*.{kind}.parquet")
    head = [f"# {fmt} v{VERSION}"] + [f"# {k}: {v}" for k, v in meta.items()
                                       if k not in ("format", "version")]
    body = rows.copy()
    for c in bool_columns:
        if c in body:
            body[c] = np.where(body[c].to_numpy(bool), "true", "false")
    for c in body.columns:
        if all_float or body[c].dtype.kind == "f":
            body[c] = ["" if math.isnan(v) else repr(float(v))
                       for v in body[c].to_numpy(float)]
    text = "\n".join(head) + "\n" + body.to_csv(index=False, lineterminator="\n")
    write_bytes(p, text.encode("utf-8"))
    return p


# -- into gaitval's per-scan track ---------------------------------------------------------
def _swing_from_speed(speed: np.ndarray) -> np.ndarray:
    """Swing by hysteresis on the leg speed (seed 000 Table 2 thresholds)."""
    out = np.zeros(len(speed), bool)
    state = False
    for i, v in enumerate(speed):
        if np.isfinite(v):
            if not state and v > V_SW_TH:
                state = True
            elif state and v < V_ST_TH:
                state = False
        out[i] = state
    return out


#: a converted time stamp this close to a scan's is that scan's (clock conversion rounding)
SNAP_S = 1e-6


def snap_to_scans(t: np.ndarray, scan_t: np.ndarray, tol_s: float = SNAP_S) -> np.ndarray:
    """``t`` with each time within ``tol_s`` of a scan time replaced by that scan time: a
    tracker's time stamp names the scan it tracked, and the mocap-to-sensor clock
    conversion (a subtraction and a division and back) moves it by a few 1e-16 s, enough to
    put a scan that lies on a TUG phase bound into the other phase."""
    t = np.asarray(t, float).copy()
    s = np.sort(np.asarray(scan_t, float))
    if not len(s) or not len(t):
        return t
    i = np.clip(np.searchsorted(s, t), 1, len(s) - 1) if len(s) > 1 else np.zeros(len(t), int)
    left, right = s[np.maximum(i - 1, 0)], s[i]
    near = np.where(np.abs(t - left) <= np.abs(right - t), left, right)
    hit = np.abs(near - t) <= tol_s
    t[hit] = near[hit]
    return t


def _where(rows: pd.DataFrame, meta: dict, i: int, field: str) -> str:
    """Row ``i`` of :func:`read_tracks` / :func:`people_to_legs` rows, as the file names
    it: a CSV line, a Parquet data row, or a bag topic's message (``msg``), with the field."""
    if "msg" in rows and np.isfinite(rows["msg"].iloc[i]):
        f = {"t_s": "header.stamp", "x": "position.x", "y": "position.y"}.get(field, field)
        return f"{meta.get('source', 'topic')}, message {int(rows['msg'].iloc[i])}, field {f}"
    kind, first = meta.get("_row", ("data row", 1))
    return f"{kind} {first + i}, column {field!r}"


#: a leg farther from the laser than its range by this much is no leg it saw (m)
RANGE_MARGIN_M = 1.0
#: every position closer to the laser than this: not in metres (m)
MIN_DISTANCE_M = 0.05


def _check_distances(rows, meta, x, y, max_range_m, path, trial) -> None:
    """Positions (sensor frame, metres) the laser can have seen: none beyond its range,
    not all at its origin (wrong ``units``, or ``frame``)."""
    d = np.hypot(x, y)
    ok = np.isfinite(d)
    if not ok.any():
        return
    head = f"header units {meta['units']!r}, frame {meta['frame']!r}"
    far = ok & (d > max_range_m + RANGE_MARGIN_M)
    if np.median(d[ok]) > max_range_m + RANGE_MARGIN_M:   # most, not one diverged track
        i = int(np.flatnonzero(far)[0])
        raise _err(path, f"{_where(rows, meta, i, 'x')}: position "
                   f"({rows['x_m'].iloc[i]:.6g}, {rows['y_m'].iloc[i]:.6g}) m is "
                   f"{d[i]:.1f} m from the laser, beyond its range ({max_range_m:g} m), "
                   f"as are {far.sum()} of {ok.sum()} positions ({head})", trial,
                   hint="positions in millimetres need 'units: mm'; positions in the "
                        "mocap field need 'frame: mocap'")
    if d[ok].max() < MIN_DISTANCE_M:
        i = int(np.flatnonzero(ok)[0])
        raise _err(path, f"{_where(rows, meta, i, 'x')}: every position lies within "
                   f"{MIN_DISTANCE_M * 100:g} cm of the laser (largest {d[ok].max():.3g} m; "
                   f"{head})", trial, hint="positions in metres need 'units: m'")


def tracks_to_sensor(rows: pd.DataFrame, meta: dict, registration: dict | None = None, *,
                     path=None, trial: str | None = None,
                     t_range: tuple[float, float] | None = None,
                     tolerance_s: float = 0.0, scan_t: np.ndarray | None = None,
                     max_range_m: float | None = None) -> pd.DataFrame:
    """Exchange rows (from :func:`read_tracks`) as gaitval's per-scan leg track.

    Parameters
    ----------
    rows, meta
        :func:`read_tracks` output.
    registration : dict, optional
        The trial's registration record (``registration.json``: ``x_m``, ``y_m``,
        ``yaw_rad``, ``clock_offset_s``, ``clock_drift_ppm``); needed when the file's
        frame or clock is ``mocap``.
    t_range : (float, float), optional
        The recording's first and last scan time on the sensor clock; a track time stamp
        (after the clock conversion) outside it by more than ``tolerance_s`` is an error
        naming the row.
    scan_t : ndarray, optional
        The recording's scan times (sensor clock): a converted time stamp within
        :data:`SNAP_S` of one becomes that scan's time (:func:`snap_to_scans`).
    max_range_m : float, optional
        The laser's range: most positions (their median; in the sensor frame, after the
        conversion) farther than this + :data:`RANGE_MARGIN_M` (a track that diverged
        far in a few scans is a tracker's result, kept), or every position within
        :data:`MIN_DISTANCE_M` of the laser, is an error naming the row and the header's
        ``units`` (and ``frame``): positions in millimetres declared as metres, or the
        reverse, or in another frame.

    Returns
    -------
    DataFrame
        :data:`TRACK_COLUMNS`, sorted by time and side, on the sensor clock in the sensor
        frame.  Columns the file lacks are filled as docs/formats.md says: ``k`` = the
        index of the time stamp, velocities by central differences, ``observed`` = a
        position is given, ``interpolated`` false, ``pattern`` ``UO`` where not observed
        (else empty), ``phase`` −1, ``swing`` from the speed (hysteresis between
        v_st_th = 0.47 and v_sw_th = 0.93 m/s, seed 000 Table 2).
    """
    if "side" not in rows:
        raise _err(path, "the file gives people (column 'person'), not legs; the leg "
                   "evaluation needs one row per leg (column 'side')", trial,
                   hint="a bag whose people are legs: set the method's legs: {L: id, R: "
                        "id}")
    reg = registration or {}
    _check_registration(path, trial, meta["frame"], meta["clock"], reg)
    t = rows["t_s"].to_numpy(float)
    if meta["clock"] == "mocap":
        # docs/formats.md, Clock: t_sensor = offset + (1 + drift ppm 1e-6) t_mocap
        drift = float(reg.get("clock_drift_ppm") or 0.0)
        t = float(reg["clock_offset_s"]) + (1.0 + drift * 1e-6) * t
    if scan_t is not None:      # also a bag's integer sec + nanosec stamps (1e-9 s steps)
        t = snap_to_scans(t, scan_t)
    if t_range is not None:
        lo, hi = t_range[0] - tolerance_s, t_range[1] + tolerance_s
        out_of = (t < lo) | (t > hi)
        if out_of.any():
            i = int(np.flatnonzero(out_of)[0])
            line = _where(rows, meta, i, "t_s")
            c0 = float(meta.get("clock_offset_s") or 0.0)
            off = f" after the header's clock_offset_s {c0!r} s" if c0 else ""
            raise _err(path, f"{line}: time stamp {float(rows['t_s'].iloc[i]) - c0!r} s "
                       f"({meta['clock']} clock{off}; {t[i]:.4f} s on the sensor clock) is "
                       f"outside the recording ({t_range[0]:.4f} to {t_range[1]:.4f} s on "
                       "the sensor clock)", trial,
                       hint="check the header's clock and the trial's clock offset")
    x, y = rows["x_m"].to_numpy(float), rows["y_m"].to_numpy(float)
    has_v = "vx_mps" in rows and "vy_mps" in rows
    vx = rows["vx_mps"].to_numpy(float) if has_v else None
    vy = rows["vy_mps"].to_numpy(float) if has_v else None
    if meta["frame"] == "mocap":
        # inverse of p_f = R(yaw) p_s + [x, y] (docs/formats.md, Sensor pose)
        c, s = math.cos(float(reg["yaw_rad"])), math.sin(float(reg["yaw_rad"]))
        dx, dy = x - float(reg["x_m"]), y - float(reg["y_m"])
        x, y = c * dx + s * dy, -s * dx + c * dy
        if has_v:
            vx, vy = c * vx + s * vy, -s * vx + c * vy
    if max_range_m is not None:
        _check_distances(rows, meta, x, y, float(max_range_m), path, trial)
    df = pd.DataFrame({"t_sensor_s": t, "side": rows["side"].to_numpy(object),
                       "x_m": x, "y_m": y})
    if has_v:
        df["vx_mps"], df["vy_mps"] = vx, vy
    for c in ("k", "observed", "pattern", "phase", "swing", "interpolated"):
        if c in rows:
            df[c] = rows[c].to_numpy()
    df = df.sort_values(["t_sensor_s", "side"], kind="stable").reset_index(drop=True)
    if "k" not in df:
        tt = df["t_sensor_s"].to_numpy(float)
        idx = (np.clip(np.searchsorted(scan_t, tt), 0, len(scan_t) - 1)
               if scan_t is not None and len(scan_t) else None)
        if idx is not None and np.array_equal(np.asarray(scan_t)[idx], tt):
            df["k"] = idx.astype(np.int64)      # the scan each time stamp names
        else:
            df["k"] = pd.factorize(df["t_sensor_s"])[0].astype(np.int64)
    finite = np.isfinite(df["x_m"].to_numpy(float)) & np.isfinite(df["y_m"].to_numpy(float))
    if not has_v:
        df["vx_mps"], df["vy_mps"] = np.nan, np.nan
        for side in SIDES:
            m = (df["side"] == side).to_numpy() & finite
            if m.sum() >= 2:
                tt = df.loc[m, "t_sensor_s"].to_numpy(float)
                df.loc[m, "vx_mps"] = np.gradient(df.loc[m, "x_m"].to_numpy(float), tt)
                df.loc[m, "vy_mps"] = np.gradient(df.loc[m, "y_m"].to_numpy(float), tt)
    if "observed" not in df:
        df["observed"] = finite
    if "interpolated" not in df:
        df["interpolated"] = False
    if "pattern" not in df:
        df["pattern"] = np.where(df["observed"].to_numpy(bool), "", "UO").astype(object)
        df.loc[~finite, "pattern"] = ""
    if "phase" not in df:
        df["phase"] = np.int64(-1)
    if "swing" not in df:
        df["swing"] = False
        for side in SIDES:
            m = (df["side"] == side).to_numpy()
            sp = np.hypot(df.loc[m, "vx_mps"].to_numpy(float),
                          df.loc[m, "vy_mps"].to_numpy(float))
            df.loc[m, "swing"] = _swing_from_speed(sp)
    df = df[list(TRACK_COLUMNS)]
    df = df.astype({"k": np.int64, "phase": np.int64, "observed": bool, "swing": bool,
                    "interpolated": bool})
    df["pattern"] = df["pattern"].astype(object)
    df["side"] = df["side"].astype(object)
    return df


# -- ROS 1/2 bag topics of leg_tracker and people_msgs --------------------------------------
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
        :func:`write_tracks`.
    """
    from gaitval.io.annotations_bag import _register_custom_types
    from gaitval.io.rosbag import _open

    p = Path(path)
    reader = _open(p, trial)
    try:
        _register_custom_types(reader)
        conns = _bag_topic(reader, topic, BAG_PEOPLE_TYPES + (BAG_LEG_DETECTIONS,), p, trial)
        msgtype, name = conns[0].msgtype, conns[0].topic
        if msgtype == BAG_LEG_DETECTIONS:
            raise _err(p, f"topic {name} holds {msgtype}: leg detections of one scan "
                       "without identity or side, not tracks", trial,
                       hint="record the tracker's people topic (leg_tracker/PersonArray, "
                       "/people_tracked) or write the legs' tracks as a *.tracks.csv; "
                       "detections are scored by 'gaitval leg-detections'")
        if msgtype not in BAG_PEOPLE_TYPES:
            raise _err(p, f"topic {name} holds {msgtype}, not one of "
                       f"{', '.join(BAG_PEOPLE_TYPES)}", trial)
        scan_frames = _scan_frames(reader)
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
    finally:
        reader.close()
    if not rows:
        raise _err(p, f"topic {name} holds no person", trial)
    _check_frames(p, name, frames, scan_frames, trial)
    df = pd.DataFrame(rows, columns=["t_s", "person", "x", "y", "msg"])
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
    df = df.sort_values(["t_s", "person"], kind="stable")     # msg: where errors point
    meta = {"format": FORMAT, "version": VERSION, "units": "m", "frame": "sensor",
            "clock": "sensor", "source": f"{msgtype} on {name}"}
    return df.reset_index(drop=True), meta


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
    from gaitval.io.annotations_bag import _register_custom_types
    from gaitval.io.rosbag import _open

    p = Path(path)
    reader = _open(p, trial)
    try:
        _register_custom_types(reader)
        conns = _bag_topic(reader, topic, (BAG_LEG_DETECTIONS,), p, trial)
        msgtype, name = conns[0].msgtype, conns[0].topic
        if msgtype != BAG_LEG_DETECTIONS:
            raise _err(p, f"topic {name} holds {msgtype}, not {BAG_LEG_DETECTIONS}", trial)
        scan_frames = _scan_frames(reader)
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
    finally:
        reader.close()
    if not stamps:
        raise _err(p, f"topic {name} has no message", trial)
    _check_frames(p, name, frames, scan_frames, trial)
    df = pd.DataFrame(rows, columns=["t_s", "msg", "x_m", "y_m", "confidence"])
    return df, {"source": f"{msgtype} on {name}", "n_messages": len(stamps),
                "t_messages": stamps}


def people_to_legs(rows: pd.DataFrame, legs: dict, *, path=None, trial: str | None = None,
                   topic: str = "") -> pd.DataFrame:
    """People rows (``t_s, person, x, y`` in metres, :func:`read_bag_tracks`) as leg rows
    (``t_s, side, x_m, y_m``, :func:`read_tracks`' columns, and ``msg`` when the people
    rows have it): ``legs`` maps each side to
    the person id that tracked it (``{"L": "1", "R": "2"}``; a PoseArray's index), for a
    tracker that publishes each leg as a person.  Other ids are dropped.  A time stamp
    where one leg's id is absent gets that leg without a position (not observed: the
    tracker had no track); an id that never appears is an error naming it."""
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


# -- leg detections without identity (issue 37; docs/formats.md, "Leg detections") ------
DET_FORMAT = "gaitval-detections"
DET_META_KEY = b"gaitval:detections"
#: the columns of a detections file (required: t_s, x, y)
DET_COLUMNS = ("t_s", "x", "y", "confidence")


def read_detections(path: str | Path, *, trial: str | None = None
                    ) -> tuple[pd.DataFrame, dict]:
    """Read a ``*.detections.csv`` or ``*.detections.parquet`` file: per scan, the legs a
    detector found, without identity or side (leg_tracker's ``LegArray`` as a file).

    One row per detection; a scan in which the detector ran and found no leg is one row
    with ``x``, ``y`` empty (it is scored as a scan with both legs missed).  The header is
    that of the track format (``units``, ``frame``, ``clock``), with the first line
    ``# gaitval-detections v1`` (Parquet: schema metadata key ``gaitval:detections``).

    Returns
    -------
    (DataFrame, dict)
        Rows ``t_s, msg, x_m, y_m`` (and ``confidence`` when given): one per detection,
        in metres, on the header's clock (plus its ``clock_offset_s``, when given) and
        frame; ``msg`` numbers the file's distinct
        time stamps (1-based); and the header with ``source`` (default: the file name),
        ``n_messages`` and ``t_messages`` (every time stamp, detections or not) — the shape
        of :func:`read_bag_leg_detections`'s result.

    Raises
    ------
    FileFormatError
        Naming the file, the field or column and the line (CSV) or data row (Parquet): a
        wrong first line, version, units, frame or clock, a missing or unknown column, a
        non-number, one of ``x``, ``y`` empty without the other, no rows.
    """
    p = Path(path)
    meta, names, cols, where, meta_lines, first_line = open_exchange(
        p, trial, "detections", DET_FORMAT, DET_META_KEY, DET_COLUMNS, ("t_s", "x", "y"),
        "detections have no side or person: a file with legs' identities is a track file")
    scale = UNITS[meta["units"]]
    t = _on_header_clock(_floats(p, "t_s", cols["t_s"], where, trial, finite=True), meta)
    x = _floats(p, "x", cols["x"], where, trial, finite=False) * scale
    y = _floats(p, "y", cols["y"], where, trial, finite=False) * scale
    half = np.isnan(x) != np.isnan(y)
    if half.any():
        i = int(np.flatnonzero(half)[0])
        raise _err(p, f"{where(i)}: one of 'x', 'y' is empty and the other not (both "
                   "empty: a scan without a detection)", trial)
    inf = np.isinf(x) | np.isinf(y)
    if inf.any():
        i = int(np.flatnonzero(inf)[0])
        raise _err(p, f"{where(i)}: a non-finite position", trial)
    stamps = np.unique(t)
    out = pd.DataFrame({"t_s": t, "msg": np.searchsorted(stamps, t) + 1, "x_m": x, "y_m": y})
    if "confidence" in names:
        out["confidence"] = _floats(p, "confidence", cols["confidence"], where, trial,
                                    finite=False)
    out["_row"] = np.arange(len(out)) + first_line
    out = out[np.isfinite(out["x_m"].to_numpy())].reset_index(drop=True)
    meta = {**meta, "source": str(meta.get("source") or p.name),
            "n_messages": int(len(stamps)), "t_messages": [float(v) for v in stamps],
            "_row": ("line" if meta_lines is not None else "row", first_line)}
    return out, meta


def write_detections(rows: pd.DataFrame, path: str | Path, *, units: str = "m",
                     frame: str = "sensor", clock: str = "sensor", **extra) -> Path:
    """Write detection rows (``t_s, x, y[, confidence]``, positions in ``units``; a scan
    without a detection a row with ``x``, ``y`` NaN) as ``*.detections.csv`` or
    ``*.detections.parquet``, atomically (CSV floats as their shortest exact text)."""
    p = Path(path)
    meta = _check_meta({"format": DET_FORMAT, "version": VERSION, "units": units,
                        "frame": frame, "clock": clock}, p, None, fmt=DET_FORMAT,
                       meta_key=DET_META_KEY)
    meta.update({k: str(v) for k, v in extra.items()})
    rows = rows[[c for c in DET_COLUMNS if c in rows.columns]].reset_index(drop=True)
    return _write_rows(p, rows, meta, DET_FORMAT, DET_META_KEY, "detections", all_float=True)


def detections_to_sensor(det: pd.DataFrame, meta: dict, registration: dict | None = None,
                         *, path=None, trial: str | None = None,
                         scan_t: np.ndarray | None = None, tolerance_s: float = 0.0,
                         max_range_m: float | None = None) -> tuple[pd.DataFrame, list]:
    """Detections (:func:`read_detections` or :func:`read_bag_leg_detections`) on the
    sensor clock in the laser frame, as :func:`tracks_to_sensor` converts tracks: with
    ``clock: mocap`` ``t_sensor = clock_offset_s + (1 + clock_drift_ppm 1e-6) t``, with
    ``frame: mocap`` ``p_s = R(-yaw) (p - [x, y])`` (the trial's ``registration``); a
    time within 1 µs of a scan's (``scan_t``) becomes that scan's.  With ``scan_t`` a time
    stamp outside the recording (± ``tolerance_s``) is an error naming its row; with
    ``max_range_m`` so are positions beyond the laser's range or all at its origin (wrong
    units or frame).  Returns the rows (``t_s`` now on the sensor clock) and every message's
    time on the sensor clock."""
    frame, clock = meta.get("frame", "sensor"), meta.get("clock", "sensor")
    reg = registration or {}
    _check_registration(path, trial, frame, clock, reg)
    det = det.copy()
    t, tm = det["t_s"].to_numpy(float), np.asarray(meta["t_messages"], float)
    if clock == "mocap":
        drift = 1.0 + float(reg.get("clock_drift_ppm") or 0.0) * 1e-6
        t, tm = float(reg["clock_offset_s"]) + drift * t, float(reg["clock_offset_s"]) + drift * tm
    if scan_t is not None and len(scan_t):
        t, tm = snap_to_scans(t, scan_t), snap_to_scans(tm, scan_t)
        lo, hi = float(np.min(scan_t)) - tolerance_s, float(np.max(scan_t)) + tolerance_s
        out_of = (tm < lo) | (tm > hi)
        if out_of.any():
            i = int(np.flatnonzero(out_of)[0])
            c0 = float(meta.get("clock_offset_s") or 0.0)
            off = f" after the header's clock_offset_s {c0!r} s" if c0 else ""
            raise _err(path, f"time stamp {float(meta['t_messages'][i]) - c0!r} s ({clock} "
                       f"clock{off}; {tm[i]:.4f} s on the sensor clock) is outside the "
                       "recording "
                       f"({lo + tolerance_s:.4f} to {hi - tolerance_s:.4f} s on the sensor "
                       f"clock), as are {int(out_of.sum())} of {len(tm)} time stamps", trial,
                       hint="check the header's clock and the trial's clock offset")
    x, y = det["x_m"].to_numpy(float), det["y_m"].to_numpy(float)
    if frame == "mocap":
        c, s = math.cos(float(reg["yaw_rad"])), math.sin(float(reg["yaw_rad"]))
        dx, dy = x - float(reg["x_m"]), y - float(reg["y_m"])
        x, y = c * dx + s * dy, -s * dx + c * dy
    det["t_s"], det["x_m"], det["y_m"] = t, x, y
    if max_range_m is not None and len(det):
        _check_detection_distances(det, meta, x, y, float(max_range_m), path, trial)
    return det.drop(columns=["_row"], errors="ignore"), [float(v) for v in tm]


def _check_detection_distances(det, meta, x, y, max_range_m, path, trial) -> None:
    """As :func:`_check_distances` for tracks: most detections beyond the laser's range
    (+ :data:`RANGE_MARGIN_M`), or all within :data:`MIN_DISTANCE_M` of it, are wrong
    units or frame; the error names the first such detection's line (file) or message
    (bag)."""
    d = np.hypot(x, y)
    head = f"header units {meta.get('units', 'm')!r}, frame {meta.get('frame', 'sensor')!r}"

    def at(i):
        if "_row" in det:
            return f"{meta.get('_row', ('line', 0))[0]} {int(det['_row'].iloc[i])}"
        return f"{meta.get('source', 'topic')}, message {int(det['msg'].iloc[i])}"

    far = d > max_range_m + RANGE_MARGIN_M
    if np.median(d) > max_range_m + RANGE_MARGIN_M:
        i = int(np.flatnonzero(far)[0])
        raise _err(path, f"{at(i)}: detection ({x[i]:.6g}, {y[i]:.6g}) m (laser frame) is "
                   f"{d[i]:.1f} m from the laser, beyond its range ({max_range_m:g} m), as "
                   f"are {int(far.sum())} of {len(d)} detections ({head})", trial,
                   hint="positions in millimetres need 'units: mm'; positions in the "
                        "mocap field need 'frame: mocap'")
    if d.max() < MIN_DISTANCE_M:
        raise _err(path, f"{at(0)}: every detection lies within {MIN_DISTANCE_M * 100:g} cm "
                   f"of the laser (largest {d.max():.3g} m; {head})", trial,
                   hint="positions in metres need 'units: m'")
