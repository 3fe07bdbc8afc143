"""``gaitval validate --deep``: open every file of a trial sheet with its loader.

The sheet check (:mod:`gaitval.io.trialsheet`) proves that the files exist; this proves
that they load: each file named by a valid row — the C3D, the sensor log (scan log, ROS bag
topic, ultrasonic log) and the annotations (rater CSV, position CSV or the bag's annotation
topic) — is read with the loader the pipeline uses, in a pool of processes, and every
problem is returned at once, each naming the row, the trial, the column and the file.

A loader's own error (a :class:`~gaitval.errors.GaitvalError`) is reported as it is; any
other exception is a loader bug and is reported as one (type and message), so a deep check
never ends in a traceback.  A file that loads but holds nothing (a C3D without markers,
a log without samples) is a problem too.
"""
from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from gaitval.errors import GaitvalError, TrialSheetError


@dataclass(frozen=True)
class FileTask:
    """One file of one row to open: ``what`` picks the loader."""

    row_line: int
    trial: str
    column: str
    what: str          # "c3d", "sensor", "annotations", "positions", "bag_annotations"
    path: str
    sensor_kind: str = ""
    topic: str = ""


def tasks_of(df) -> list[FileTask]:
    """The files of every row of a validated sheet (:func:`sheet_problems`' frame)."""
    out = []
    lines = df.attrs.get("row_lines", {})
    for i, r in enumerate(df.to_dict("records")):
        line = int(lines.get(r["trial"], i + 2))
        if r.get("mocap_path"):
            out.append(FileTask(line, r["trial"], "mocap_file", "c3d", r["mocap_path"]))
        if r.get("sensor_path"):
            out.append(FileTask(line, r["trial"], "sensor_file", "sensor", r["sensor_path"],
                                r["sensor_kind"], r.get("sensor_topic") or ""))
        ann = r.get("annotation_path") or ""
        if ann:
            what = "positions" if ann.endswith(".positions.csv") else "annotations"
            out.append(FileTask(line, r["trial"], "annotation_file", what, ann))
        if r.get("annotation_topic"):
            out.append(FileTask(line, r["trial"], "annotation_topic", "bag_annotations",
                                r["sensor_path"], topic=r["annotation_topic"]))
    return out


def _load(task: FileTask) -> str | None:
    """None when the file loads and holds data, else the problem in one sentence."""
    try:
        n = _count(task)
    except GaitvalError as exc:
        return exc.problem + (f" ({exc.hint})" if exc.hint else "")
    except MemoryError:
        return "the loader ran out of memory"
    except Exception as exc:                      # noqa: BLE001 -- a loader bug, said once
        return f"the loader failed unexpectedly ({type(exc).__name__}: {exc})"
    return None if n > 0 else "loads but holds no data"


def _count(t: FileTask) -> int:
    """What the file holds (markers × frames, samples, events): loads it."""
    if t.what == "c3d":
        from gaitval.io.c3d_read import read_c3d
        m = read_c3d(t.path, trial=t.trial)
        return len(m.labels) * m.n_frames
    if t.what == "sensor":
        from gaitval.io.ingest import read_sensor
        s = read_sensor({"sensor_path": t.path, "trial": t.trial,
                         "sensor_kind": t.sensor_kind, "sensor_topic": t.topic})
        return int(getattr(s, "n_scans", 0) or len(getattr(s, "t", ())))
    if t.what == "annotations":
        from gaitval.io.annotations import read_annotations
        events, _meta = read_annotations(t.path, trial=t.trial)
        return max(1, len(events))     # a trial without events is legitimate
    if t.what == "positions":
        from gaitval.io.annotations_bag import read_position_csv
        return len(read_position_csv(t.path, trial=t.trial))
    from gaitval.io.annotations_bag import read_bag_annotations
    positions, _meta = read_bag_annotations(t.path, t.topic, trial=t.trial)
    return len(positions)


def deep_problems(df, sheet, jobs: int | None = None) -> list[GaitvalError]:
    """Open every file of the sheet's valid rows; one :class:`TrialSheetError` per file
    that does not load, naming row, trial, column and file."""
    tasks = tasks_of(df)
    if not tasks:
        return []
    jobs = max(1, min(jobs or os.cpu_count() or 1, len(tasks)))
    if jobs == 1:
        results = [_load(t) for t in tasks]
    else:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            results = list(pool.map(_load, tasks, chunksize=1))
    return [TrialSheetError(f"row {t.row_line} (trial {t.trial!r}), column {t.column!r}: "
                            f"{why}", path=t.path, trial=t.trial)
            for t, why in zip(tasks, results) if why is not None]
