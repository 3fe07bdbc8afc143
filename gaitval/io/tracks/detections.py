"""Leg detections without identity as a file (docs/formats_external.md, "Leg detections"):
``*.detections.csv`` and ``*.detections.parquet``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import (UNITS, VERSION, _check_meta, _err, _floats,
                                        _on_header_clock, open_exchange)
from gaitval.io.tracks.write import _write_rows


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
        of :func:`~gaitval.io.tracks.bag.read_bag_leg_detections`'s result.

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
