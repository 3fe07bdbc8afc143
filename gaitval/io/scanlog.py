"""gaitval's open laser scan-log format (``*.scan.parquet``), reader and writer.

Format (version 1), documented in full in ``docs/formats.md``
------------------------------------------------------------
One Apache Parquet file, one row per scan, in the order the sensor produced them:

* ``t_s`` (float64): the scan's timestamp in seconds on the **sensor's own clock** (time of
  the first beam, as ``sensor_msgs/LaserScan.header.stamp``).
* ``ranges`` (fixed-size list of ``n_beams`` values): the ranges, beam 0 first.  Integer
  millimetres (uint16/uint32) when ``range_unit`` is ``mm`` — 0 means "no return", as a
  Hokuyo reports it — or float metres when ``range_unit`` is ``m`` (NaN/inf: no return).

The schema metadata key ``gaitval:scanlog`` holds a JSON object::

    {"format": "gaitval-scanlog", "version": 1,
     "angle_min_rad": -2.356194490192345, "angle_increment_rad": 0.004363323129985824,
     "n_beams": 1081, "range_unit": "mm", "range_min_m": 0.1, "range_max_m": 30.0,
     "sensor_model": "Hokuyo UTM-30LX", "mounting_height_m": 0.27,
     "scan_time_s": 0.025, "frame": "x forward, y left, angles counter-clockwise"}

Beam ``i`` points at ``angle_min_rad + i * angle_increment_rad`` in the sensor frame
(x forward, y to the left, counter-clockwise positive: the ROS convention).

Reading it without gaitval::

    import json, numpy as np, pyarrow.parquet as pq
    tab = pq.read_table("trial.scan.parquet")
    meta = json.loads(tab.schema.metadata[b"gaitval:scanlog"])
    t = tab["t_s"].to_numpy()
    ranges = np.stack(tab["ranges"].to_numpy(zero_copy_only=False))  # mm, 0 = no return
"""
from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import atomic_path
from gaitval.io.guard import (column_kind, enough_rows, json_meta, loader,
                              number, text_field, version_field)
from gaitval.types import ScanSeries

log = logging.getLogger("gaitval.io.scanlog")

META_KEY = b"gaitval:scanlog"
FORMAT = "gaitval-scanlog"
VERSION = 1
SUFFIX = ".scan.parquet"
#: physical bounds of the metadata (a scan of a 2-D laser scanner: 5-100 Hz, <= 10k beams)
MAX_SCAN_TIME_S = 10.0
MAX_BEAMS = 100_000
#: scans x beams a scan log may hold (float64: 1 GB); a longer recording is split into
#: trials (half an hour of a 40 Hz, 1081-beam scanner is 78 M).
MAX_RANGE_VALUES = 125_000_000
#: a scan spans at most one turn (radians, with a little slack for rounding)
MAX_SPAN_RAD = 2 * np.pi + 1e-3
#: the beams of one scan are taken within this many seconds (time_increment x n_beams)
MAX_SWEEP_S = 1.0


def check_scan_geometry(where: str, n_beams: int, angle_min: float, angle_increment: float,
                        time_increment: float | None, path, trial: str | None) -> None:
    """Angles and beam timing within physical bounds (shared with the bag reader): the
    first beam within one turn of 0, the beams spanning at most one turn, and a sweep
    (``time_increment`` x beams) of at most :data:`MAX_SWEEP_S`.  ``where`` names the
    fields' place ("scan-log metadata", "LaserScan topic /scan, first message")."""
    if abs(angle_min) > MAX_SPAN_RAD:
        raise FileFormatError(f"{where}: angle_min is {angle_min:g} rad, more than one "
                              "turn from 0", path=path, trial=trial)
    if abs(angle_increment) * max(n_beams - 1, 1) > MAX_SPAN_RAD:
        raise FileFormatError(f"{where}: angle_increment {angle_increment:g} rad x "
                              f"{n_beams} beams spans more than one turn", path=path,
                              trial=trial)
    if time_increment is not None and not (np.isfinite(time_increment) and
                                           abs(time_increment) * n_beams <= MAX_SWEEP_S):
        raise FileFormatError(f"{where}: time_increment is {time_increment!r} s; over "
                              f"{n_beams} beams a scan must take a finite time of at most "
                              f"{MAX_SWEEP_S:g} s", path=path, trial=trial)


def clean_ranges(ranges: np.ndarray, range_min: float, range_max: float
                 ) -> tuple[np.ndarray, int]:
    """Map every kind of "no return" to NaN (the one documented value).

    inf, NaN, zero/negative, below ``range_min`` and above ``range_max`` all become NaN.
    Returns the cleaned float64 array and the number of beams mapped.
    """
    r = np.asarray(ranges, dtype=np.float64).copy()
    with np.errstate(invalid="ignore"):
        bad = ~np.isfinite(r) | (r <= 0.0) | (r < range_min) | (r > range_max)
    r[bad] = np.nan
    return r, int(bad.sum())


def check_timestamps(t: np.ndarray) -> pd.DataFrame:
    """Report non-monotonic or duplicated timestamps; never reorder.

    Returns a DataFrame ``index, t_s, problem`` with one row per offending scan (the
    later scan of each bad pair).
    """
    t = np.asarray(t, dtype=np.float64)
    d = np.diff(t)
    rows = []
    for i in np.flatnonzero(d == 0.0):
        rows.append((int(i + 1), float(t[i + 1]), "duplicate"))
    for i in np.flatnonzero(d < 0.0):
        rows.append((int(i + 1), float(t[i + 1]), "non-monotonic"))
    rows.sort()
    return pd.DataFrame(rows, columns=["index", "t_s", "problem"])


def write_scanlog(path: str | Path, series: ScanSeries, *, range_unit: str = "mm",
                  scan_time_s: float | None = None) -> Path:
    """Write ``series`` as a gaitval scan log (atomically).

    With ``range_unit="mm"`` ranges are rounded to whole millimetres (the sensor's
    quantisation) and "no return" (NaN) is written as 0.
    """
    import pyarrow as pa
    import pyarrow.parquet as pq

    r = np.asarray(series.ranges, dtype=np.float64)
    n, nb = r.shape
    if range_unit == "mm":
        mm = np.where(np.isfinite(r), np.rint(r * 1000.0), 0.0)
        dtype = np.uint16 if mm.max(initial=0) < 65535 else np.uint32
        flat = pa.array(mm.astype(dtype).ravel())
    elif range_unit == "m":
        flat = pa.array(r.astype(np.float32).ravel())
    else:
        raise ValueError(f"range_unit must be 'mm' or 'm', not {range_unit!r}")
    meta = {
        "format": FORMAT, "version": VERSION,
        "angle_min_rad": float(series.angle_min),
        "angle_increment_rad": float(series.angle_increment),
        "n_beams": int(nb), "range_unit": range_unit,
        "range_min_m": float(series.range_min), "range_max_m": float(series.range_max),
        "sensor_model": series.sensor_model,
        "mounting_height_m": (None if series.mounting_height_m is None
                              else float(series.mounting_height_m)),
        "scan_time_s": scan_time_s,
        "frame": "x forward, y left, angles counter-clockwise (ROS LaserScan)",
    }
    table = pa.table({
        "t_s": pa.array(np.asarray(series.t, dtype=np.float64)),
        "ranges": pa.FixedSizeListArray.from_arrays(flat, nb),
    })
    table = table.replace_schema_metadata({META_KEY: json.dumps(meta).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
    return Path(path)


@loader("scan log")
def read_scanlog(path: str | Path, *, trial: str | None = None) -> ScanSeries:
    """Read a gaitval scan log into a :class:`~gaitval.types.ScanSeries` (metres, NaN = no return).

    Raises
    ------
    FileFormatError
        Missing file, not Parquet, missing or non-JSON metadata, a metadata field that is
        missing, not a finite number, outside its bounds or contradicts another
        (``range_min_m`` above ``range_max_m``, ``angle_increment_rad`` 0), a ``format``
        other than ``gaitval-scanlog``, a version that is not a whole number from 1 to
        :data:`VERSION`, a ``sensor_model`` that is not text, fewer than 2 scans or times
        that never advance, a ``t_s`` column that is not float/integer (bool,
        timestamp), non-finite timestamps, or a ``ranges`` column whose length does not
        match ``n_beams`` or whose type does not match ``range_unit``.
    """
    return _read_scanlog(Path(path), trial)


def _read_scanlog(path: Path, trial: str | None) -> ScanSeries:
    import pyarrow.parquet as pq

    if not path.is_file():
        raise FileFormatError("scan log not found", path=path, trial=trial)
    # the footer first (schema, metadata, row count): the size is checked before a value
    # is read, so a small file announcing millions of scans of thousands of beams is
    # refused without the memory it would take
    try:
        with pq.ParquetFile(path) as pf:
            md = pf.schema_arrow.metadata or {}
            n_rows = int(pf.metadata.num_rows)
            if META_KEY not in md:
                raise FileFormatError("Parquet file has no 'gaitval:scanlog' metadata; is "
                                      "it a gaitval scan log?", path=path, trial=trial,
                                      hint="see docs/formats.md")
            meta = json_meta(md[META_KEY], META_KEY.decode(), path, trial)
            g = _meta_fields(meta, path, trial)
            if n_rows * g["n_beams"] > MAX_RANGE_VALUES:
                raise FileFormatError(
                    f"scan log announces {n_rows:,} scans x {g['n_beams']:,} beams = "
                    f"{n_rows * g['n_beams']:,} ranges; gaitval reads at most "
                    f"{MAX_RANGE_VALUES:,} per file ({MAX_RANGE_VALUES * 8 / 1e9:.1f} GB "
                    "as numbers)", path=path, trial=trial,
                    hint="split the recording into trials (one scan log per trial)")
            for col in ("t_s", "ranges"):
                if col not in pf.schema_arrow.names:
                    raise FileFormatError(f"scan log has no '{col}' column", path=path,
                                          trial=trial)
            tab = pf.read(columns=["t_s", "ranges"], use_threads=False)
    except FileFormatError:
        raise
    except Exception as exc:  # noqa: BLE001 - pyarrow: ArrowInvalid, OSError, ...
        raise FileFormatError(f"not a readable Parquet scan log: {exc}", path=path,
                              trial=trial) from None
    t, raw = _columns(tab, g["n_beams"], g["unit"], path, trial)
    enough_rows(t, 2, path, trial, what="scan log", unit="scan")
    if g["unit"] == "mm":
        raw = raw / 1000.0
    _range_plausibility(raw, g, path, trial)
    ranges, n_bad = clean_ranges(raw, g["rmin"], g["rmax"])
    return ScanSeries(
        t=t, ranges=ranges, angle_min=g["amin"], angle_increment=g["ainc"],
        range_min=g["rmin"], range_max=g["rmax"],
        sensor_model=g["model"] or "unknown",
        mounting_height_m=g["height"], source=str(path),
        timestamp_issues=check_timestamps(t), n_no_return_raw=n_bad,
        meta={k: v for k, v in meta.items() if k not in {"n_beams"}})


def _range_plausibility(raw: np.ndarray, g: dict, path: Path, trial: str | None) -> None:
    """Ranges that cannot be a recording: every range negative (no scanner measures a
    negative distance; a sign or offset error), or not one range inside
    ``[range_min_m, range_max_m]`` in the whole log (the unit or the limits are wrong):
    a FileFormatError instead of a log that loads as 100 % "no return"."""
    with np.errstate(invalid="ignore"):
        finite = np.isfinite(raw)
        n_finite = int(finite.sum())
        n_neg = int((raw < 0).sum())
        n_valid = int((finite & (raw > 0) & (raw >= g["rmin"]) & (raw <= g["rmax"])).sum())
    if n_finite and n_neg == n_finite:
        raise FileFormatError(f"every one of the {n_finite:,} ranges is negative; a laser "
                              "scanner measures distances >= 0 (a sign or offset error?)",
                              path=path, trial=trial)
    if n_finite and n_valid == 0:
        lo, hi = float(np.nanmin(raw[finite])), float(np.nanmax(raw[finite]))
        raise FileFormatError(
            f"none of the {n_finite:,} ranges lies within range_min_m..range_max_m "
            f"({g['rmin']:g}..{g['rmax']:g} m; the ranges span {lo:.4g}..{hi:.4g} m "
            f"read as {g['unit']}): the log would be all 'no return'", path=path,
            trial=trial, hint="check range_unit and the range limits in the metadata")
    if n_neg and n_neg > 0.5 * n_finite:
        log.warning("%s: %d of %d ranges are negative (read as no return)", path, n_neg,
                    n_finite)


def _meta_fields(meta: dict, path: Path, trial: str | None) -> dict:
    """The metadata fields the reader uses, checked (finite, in range, consistent)."""
    kw = {"path": path, "trial": trial, "what": "scan-log metadata"}
    text_field(meta, "format", expected=FORMAT, **kw)
    version_field(meta, VERSION, **kw)
    g = {"model": text_field(meta, "sensor_model", **kw),
         "scan_time": number(meta, "scan_time_s", above=0, optional=True, **kw),
         "n_beams": number(meta, "n_beams", above=0, integer=True, **kw),
         "amin": number(meta, "angle_min_rad", **kw),
         "ainc": number(meta, "angle_increment_rad", **kw),
         "rmin": number(meta, "range_min_m", minimum=0, **kw),
         "rmax": number(meta, "range_max_m", above=0, **kw),
         "height": number(meta, "mounting_height_m", above=0, optional=True, **kw),
         "unit": meta.get("range_unit")}
    if g["ainc"] == 0:
        raise FileFormatError("scan-log metadata field 'angle_increment_rad' is 0: every "
                              "beam would point the same way", path=path, trial=trial)
    if g["rmin"] >= g["rmax"]:
        raise FileFormatError(f"scan-log metadata: range_min_m ({g['rmin']:g}) is not below "
                              f"range_max_m ({g['rmax']:g})", path=path, trial=trial)
    if g["unit"] not in ("mm", "m"):
        raise FileFormatError(f"unknown range_unit {g['unit']!r} (expected 'mm' or 'm')",
                              path=path, trial=trial)
    if g["scan_time"] is not None and g["scan_time"] > MAX_SCAN_TIME_S:
        raise FileFormatError(f"scan-log metadata field 'scan_time_s' is {g['scan_time']:g}"
                              f" s; a scan takes at most {MAX_SCAN_TIME_S:g} s", path=path,
                              trial=trial)
    if g["n_beams"] > MAX_BEAMS:
        raise FileFormatError(f"scan-log metadata field 'n_beams' is {g['n_beams']}; a "
                              f"laser scanner has at most {MAX_BEAMS} beams", path=path,
                              trial=trial)
    inc = number(meta, "time_increment_s", optional=True, **kw)   # beam timing, if stated
    check_scan_geometry("scan-log metadata", g["n_beams"], g["amin"], g["ainc"], inc, path,
                        trial)
    return g


def _columns(tab, nb: int, unit: str, path: Path, trial: str | None
             ) -> tuple[np.ndarray, np.ndarray]:
    """``t_s`` (finite) and ``ranges`` as (n_scans, n_beams) float64."""
    import pyarrow as pa

    column_kind(tab, "t_s", ("float", "integer"), path, trial, what="scan-log column")
    try:
        t = tab["t_s"].to_numpy().astype(np.float64)
    except (pa.ArrowException, ValueError, TypeError) as exc:
        raise FileFormatError(f"column 't_s' is not numeric: {exc}", path=path,
                              trial=trial) from None
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise FileFormatError(f"column 't_s' holds {t[bad[0]]!r} at scan {int(bad[0])}; "
                              "timestamps must be finite", path=path, trial=trial)
    col = tab["ranges"].combine_chunks()
    if not pa.types.is_list(col.type) and not pa.types.is_fixed_size_list(col.type) \
            and not pa.types.is_large_list(col.type):
        raise FileFormatError(f"column 'ranges' is {col.type}, not a list of ranges per "
                              "scan", path=path, trial=trial)
    values = col.flatten()
    if not (pa.types.is_integer(values.type) or pa.types.is_floating(values.type)):
        raise FileFormatError(f"column 'ranges' holds {values.type}, not numbers",
                              path=path, trial=trial)
    if pa.types.is_integer(values.type) and unit == "m":
        raise FileFormatError(f"column 'ranges' holds {values.type} but range_unit is 'm' "
                              "(metres are stored as floats; integers are 'mm')",
                              path=path, trial=trial)
    values = values.to_numpy(zero_copy_only=False)
    if values.size != nb * len(t) or col.null_count:
        raise FileFormatError(f"ranges hold {values.size} values, expected "
                              f"{len(t)} scans x {nb} beams", path=path, trial=trial)
    return t, values.reshape(len(t), nb).astype(np.float64)
