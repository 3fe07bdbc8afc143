"""Writing leg-track files: gaitval's own per-scan track as exchange rows, and the rows as
``*.tracks.csv``/``.parquet`` (or, for :mod:`gaitval.io.tracks.detections`, a detections
file), atomically and exact to the float.
"""
from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.atomic import write_bytes, write_parquet
from gaitval.io.tracks.exchange import (BOOL_COLUMNS, COLUMNS, FORMAT, META_KEY, VERSION,
                                        _check_meta, _err)


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
    """Write exchange-format rows (columns of :data:`~gaitval.io.tracks.exchange.COLUMNS`;
    positions in ``units``) to ``*.tracks.csv`` or ``*.tracks.parquet``, atomically.
    ``extra`` header keys (e.g. ``source``) are written after the required ones.  CSV
    floats are written with the shortest text that reads back to the same float (Python's
    ``repr``), so a round trip through CSV is exact."""
    p = Path(path)
    meta = _check_meta({"format": FORMAT, "version": VERSION, "units": units,
                        "frame": frame, "clock": clock}, p, None)
    meta.update({k: str(v) for k, v in extra.items()})
    rows = rows[[c for c in COLUMNS if c in rows.columns]].reset_index(drop=True)
    return _write_rows(p, rows, meta, FORMAT, META_KEY, "tracks", bool_columns=BOOL_COLUMNS)


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
