"""gaitval's ultrasonic ranging log (``*.us.parquet``), reader and writer.

Format (version 1), documented in full in ``docs/formats.md``
------------------------------------------------------------
One Parquet file, one row per sample, in the order the system produced them:

* ``t_s`` (float64): sample time in seconds on the ultrasonic system's clock;
* ``temperature_c`` (float64): air temperature in degrees Celsius (seed 003 eq. 2);
* one column per receiver (anchor) ``A``: ``tof_A_s`` (time of flight, seconds) when
  ``quantity`` is ``tof``, or ``dist_A_m`` (metres) when it is ``distance``; NaN where no
  echo was received.

Schema metadata key ``gaitval:ultrasonic`` holds a JSON object::

    {"format": "gaitval-ultrasonic", "version": 1, "quantity": "tof",
     "anchors": [{"anchor": "R1", "x_m": 0.0, "y_m": 0.0, "z_m": 0.0}, ...],
     "transmitter": "heel", "sensor_model": "...", "frame": "..."}

The anchor geometry (receiver positions, metres, in the ultrasonic system's frame) lives in
the metadata so one file is a complete record.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import atomic_path
from gaitval.io.scanlog import check_timestamps
from gaitval.types import UltrasonicLog

META_KEY = b"gaitval:ultrasonic"
FORMAT = "gaitval-ultrasonic"
VERSION = 1
SUFFIX = ".us.parquet"


def write_ultrasonic(path: str | Path, log: UltrasonicLog, *, transmitter: str = "heel",
                     sensor_model: str = "unknown") -> Path:
    """Write an :class:`~gaitval.types.UltrasonicLog` atomically."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    ids = log.anchor_ids
    cols = {"t_s": np.asarray(log.t, dtype=np.float64),
            "temperature_c": np.asarray(log.temperature_c, dtype=np.float64)}
    if log.tof_s is not None:
        quantity, data, fmt = "tof", np.asarray(log.tof_s, dtype=np.float64), "tof_{}_s"
    elif log.distance_m is not None:
        quantity, data, fmt = "distance", np.asarray(log.distance_m, dtype=np.float64), "dist_{}_m"
    else:
        raise ValueError("UltrasonicLog has neither tof_s nor distance_m")
    for j, a in enumerate(ids):
        cols[fmt.format(a)] = data[:, j]
    meta = {"format": FORMAT, "version": VERSION, "quantity": quantity,
            "anchors": [{"anchor": str(r.anchor), "x_m": float(r.x_m), "y_m": float(r.y_m),
                         "z_m": float(r.z_m)} for r in log.anchors.itertuples()],
            "transmitter": transmitter, "sensor_model": sensor_model,
            **{k: v for k, v in log.meta.items() if isinstance(v, (str, int, float))}}
    table = pa.table(cols).replace_schema_metadata({META_KEY: json.dumps(meta).encode()})
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="zstd")
    return Path(path)


def read_ultrasonic(path: str | Path, *, trial: str | None = None) -> UltrasonicLog:
    """Read a gaitval ultrasonic log (seconds, metres, degC; NaN = no echo)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    path = Path(path)
    if not path.is_file():
        raise FileFormatError("ultrasonic log not found", path=path, trial=trial)
    try:
        tab = pq.read_table(path)
    except (pa.ArrowInvalid, OSError) as exc:
        raise FileFormatError(f"not a readable Parquet ultrasonic log: {exc}", path=path,
                              trial=trial) from None
    md = tab.schema.metadata or {}
    if META_KEY not in md:
        raise FileFormatError("Parquet file has no 'gaitval:ultrasonic' metadata",
                              path=path, trial=trial, hint="see docs/formats.md")
    meta = json.loads(md[META_KEY])
    try:
        anchors = pd.DataFrame(meta["anchors"])[["anchor", "x_m", "y_m", "z_m"]]
        quantity = meta["quantity"]
    except (KeyError, TypeError) as exc:
        raise FileFormatError(f"ultrasonic metadata incomplete: {exc}", path=path,
                              trial=trial) from None
    fmt = {"tof": "tof_{}_s", "distance": "dist_{}_m"}.get(quantity)
    if fmt is None:
        raise FileFormatError(f"unknown quantity {quantity!r} (expected 'tof' or "
                              "'distance')", path=path, trial=trial)
    need = ["t_s", "temperature_c"] + [fmt.format(a) for a in anchors["anchor"]]
    missing = [c for c in need if c not in tab.column_names]
    if missing:
        raise FileFormatError(f"ultrasonic log lacks columns {missing}", path=path,
                              trial=trial)
    df = tab.select(need).to_pandas()
    data = df[need[2:]].to_numpy(dtype=np.float64, copy=True)
    with np.errstate(invalid="ignore"):
        data[~np.isfinite(data) | (data <= 0)] = np.nan
    t = df["t_s"].to_numpy(dtype=np.float64)
    issues = check_timestamps(t)
    log = UltrasonicLog(t=t, temperature_c=df["temperature_c"].to_numpy(dtype=np.float64),
                        anchors=anchors.reset_index(drop=True), source=str(path),
                        meta={**meta, "timestamp_issues": issues})
    if quantity == "tof":
        log.tof_s = data
    else:
        log.distance_m = data
    return log
