"""Ingest: raw trial files → tidy per-trial files under ``results/<study>/ingest/<trial>/``.

One call per trial (one Snakemake job per trial).  What it writes:

``mocap.parquet``
    Tidy marker table ``frame, t_s, marker, x_m, y_m, z_m`` (metres, mocap clock, NaN for
    gaps) with schema metadata ``gaitval:mocap`` (JSON: rate_hz, first_frame, units on disk,
    source file, labels in order, meta of the loader).  The source file is stored as the
    trial sheet names it (relative to the sheet's folder), so the ingested files do not
    depend on where the study folder sits; the steps that have the sheet's row give the
    reader the absolute path (``read_mocap_parquet(..., source=row["mocap_path"])``) for
    their error messages.
``events.csv``
    C3D events ``context, label, t_s`` (may be empty).
``sensor.parquet``
    The sensor log in gaitval's own format (scan logs in float metres, NaN = no return),
    whatever the raw format was (gaitval scan log, ROS 1/2 bag, ultrasonic log).
``annotations.csv``
    Rater annotations in gaitval's format (header only when the trial has none).
``ingest.json``
    What was read: counts, rates, gaps, no-return beams, timestamp problems.

Downstream steps read these with :func:`read_mocap_parquet` and the format readers.
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval import consts as C
from gaitval.errors import FileFormatError, GaitvalError
from gaitval.io.atomic import write_arrow, write_csv, write_text
from gaitval.types import MocapTrial, ScanSeries, UltrasonicLog

MOCAP_META_KEY = "gaitval:mocap"


def read_sensor(row) -> ScanSeries | UltrasonicLog:
    """Read a trial's sensor log, whatever its format (dispatch on kind and suffix)."""
    path = Path(row["sensor_path"])
    trial = row["trial"]
    if row["sensor_kind"] == "ultrasonic":
        from gaitval.io.ultrasonic import read_ultrasonic
        return read_ultrasonic(path, trial=trial)
    if path.name.endswith(".scan.parquet"):
        from gaitval.io.scanlog import read_scanlog
        return read_scanlog(path, trial=trial)
    if path.suffix == ".bag" or path.is_dir() or path.suffix in (".db3", ".mcap"):
        from gaitval.io.rosbag import read_rosbag_scans
        return read_rosbag_scans(path, row.get("sensor_topic") or None, trial=trial)
    from gaitval.errors import FileFormatError
    raise FileFormatError("unknown LRS log format (expected *.scan.parquet, a ROS 1 .bag "
                          "or a ROS 2 bag folder)", path=path, trial=trial)


def write_mocap_parquet(mocap: MocapTrial, path: str | Path, source: str | None = None
                        ) -> Path:
    """``mocap`` as ``mocap.parquet`` (module docstring); ``source``: the file name to
    record (default ``mocap.path``).  Only the marker column is dictionary-encoded."""
    meta = {"rate_hz": mocap.rate_hz, "first_frame": mocap.first_frame,
            "units": mocap.units, "source": mocap.path if source is None else source,
            "labels": list(mocap.labels),
            "meta": {k: v for k, v in mocap.meta.items()
                     if isinstance(v, (str, int, float, bool, list, dict))}}
    return write_arrow(mocap.to_arrow(), path, dictionary=[C.MARKER],
                       metadata={MOCAP_META_KEY: json.dumps(meta, sort_keys=True,
                                                            default=str)})


def read_mocap_parquet(path: str | Path, events_path: str | Path | None = None,
                       source: str | None = None, trial: str | None = None) -> MocapTrial:
    """Rebuild a :class:`MocapTrial` from an ingested ``mocap.parquet``.

    ``source``: the trial's C3D file as ``MocapTrial.path`` (errors name it), e.g. the
    absolute ``mocap_path`` of the trial sheet's row; default the name stored at ingest
    (as the sheet gives it, relative to the sheet's folder); ``trial``: named in errors.
    Only the coordinate columns are read (the frame numbers and times follow from the
    stored rate and first frame).

    Raises
    ------
    FileFormatError
        The file is not an ingested marker table (unreadable, no ``gaitval:mocap``
        metadata, or rows that are not whole frames).
    """
    import pyarrow.parquet as pq

    try:
        pf = pq.ParquetFile(path)
        meta = json.loads(pf.schema_arrow.metadata[MOCAP_META_KEY.encode()])
        tab = pf.read(columns=[C.X, C.Y, C.Z])
    except (OSError, KeyError, TypeError, ValueError) as exc:
        raise FileFormatError(f"not an ingested mocap.parquet of gaitval ({exc})",
                              path=path, trial=trial,
                              hint="run the ingest step again") from None
    labels = meta["labels"]
    n_m = len(labels)
    n_f = tab.num_rows // n_m if n_m else 0
    if n_f * n_m != tab.num_rows:
        raise FileFormatError(f"{tab.num_rows} rows are not whole frames of {n_m} markers",
                              path=path, trial=trial, hint="run the ingest step again")
    # one row per coordinate, (3, rows), seen as (frames, markers, 3): the layout (strides
    # 8 n_m, 8, 8 rows) the readers have always been given (pandas' column block), which
    # the sums downstream follow to the last bit (a C-ordered copy changes the ultrasonic
    # noise estimate in its 13th digit)
    cols = np.empty((3, n_f * n_m))
    for i, c in enumerate((C.X, C.Y, C.Z)):
        cols[i] = tab.column(c).to_numpy()            # nulls (gaps) come back as NaN
    xyz = cols.T.reshape(n_f, n_m, 3)
    events = pd.DataFrame(columns=["context", "label", "t_s"])
    if events_path is not None and Path(events_path).is_file():
        events = pd.read_csv(events_path, keep_default_na=False)
    return MocapTrial(path=source or meta["source"], rate_hz=float(meta["rate_hz"]),
                      first_frame=int(meta["first_frame"]), labels=list(labels), xyz=xyz,
                      events=events, units=meta["units"], meta=meta.get("meta", {}))


def ingest_trial(row, out_dir: str | Path) -> dict:
    """Read one trial's raw files and write the tidy per-trial files (see module doc).

    Parameters
    ----------
    row : mapping
        One row of :func:`gaitval.io.trialsheet.load_trial_sheet`.
    out_dir : folder for this trial's files.

    Returns
    -------
    dict
        The summary written to ``ingest.json``.
    """
    from gaitval.io.annotations import COLUMNS as ANN_COLS
    from gaitval.io.annotations import read_annotations, write_annotations
    from gaitval.io.c3d import read_c3d

    out = Path(out_dir)
    trial = row["trial"]
    try:
        mocap = read_c3d(row["mocap_path"], trial=trial)
        sensor = read_sensor(row)
    except GaitvalError as exc:
        raise exc.with_context(trial=trial) from None
    write_mocap_parquet(mocap, out / "mocap.parquet", source=row["mocap_file"])
    write_csv(mocap.events, out / "events.csv")
    gaps = int(np.isnan(mocap.xyz[:, :, 0]).sum())
    summary = {
        "trial": trial, "study": row["study"], "protocol": row["protocol"],
        "subject": row["subject"], "sensor_kind": row["sensor_kind"],
        "mocap_file": row["mocap_file"], "mocap_rate_hz": mocap.rate_hz,
        "mocap_frames": mocap.n_frames, "markers": len(mocap.labels),
        "marker_samples_missing": gaps,
        "marker_missing_pct": 100.0 * gaps / max(1, mocap.xyz[:, :, 0].size),
        "events": int(len(mocap.events)), "sensor_file": row["sensor_file"],
    }
    if isinstance(sensor, ScanSeries):
        from gaitval.io.scanlog import write_scanlog
        write_scanlog(out / "sensor.parquet", sensor, range_unit="m")
        summary.update({
            "sensor_samples": sensor.n_scans, "beams": sensor.n_beams,
            "sensor_rate_hz": (float(1.0 / np.median(np.diff(sensor.t)))
                               if sensor.n_scans > 1 else float("nan")),
            "no_return_pct": 100.0 * sensor.n_no_return_raw / max(1, sensor.ranges.size),
            "timestamp_issues": int(len(sensor.timestamp_issues)),
            "sensor_height_m": (row.get("sensor_height_m")
                                if pd.notna(row.get("sensor_height_m", np.nan))
                                else sensor.mounting_height_m),
        })
    else:
        from gaitval.io.ultrasonic import write_ultrasonic
        write_ultrasonic(out / "sensor.parquet", sensor)
        data = sensor.tof_s if sensor.tof_s is not None else sensor.distance_m
        summary.update({
            "sensor_samples": int(len(sensor.t)), "anchors": len(sensor.anchor_ids),
            "sensor_rate_hz": sensor.rate_hz,
            "no_return_pct": 100.0 * float(np.isnan(data).mean()),
            "timestamp_issues": int(len(sensor.meta.get("timestamp_issues", []))),
        })
    if row.get("annotation_path"):
        try:
            ann, meta = read_annotations(row["annotation_path"], trial=trial)
        except GaitvalError as exc:
            raise exc.with_context(trial=trial) from None
        write_annotations(out / "annotations.csv", ann[ANN_COLS],
                          time_base=meta.get("time_base", "video"),
                          time_offset_s=float(meta.get("time_offset_s", 0.0)),
                          rater=meta.get("rater", ""))
        summary["annotations"] = int(len(ann))
    else:
        write_annotations(out / "annotations.csv", pd.DataFrame(columns=ANN_COLS),
                          time_base="mocap")
        summary["annotations"] = 0
    summary = {k: (float(v) if isinstance(v, (np.floating,)) else
                   int(v) if isinstance(v, np.integer) else v) for k, v in summary.items()}
    write_text(out / "ingest.json", json.dumps(summary, indent=1, sort_keys=True,
                                               default=str) + "\n")
    return summary
