"""One trial's inputs: its validated trial-sheet row and subject (kept per process, by the
files' identities) and its ingested mocap and sensor.
"""
from __future__ import annotations

import copy
from pathlib import Path

from gaitval.io.trialsheet import load_subjects, load_trial_row
from gaitval.pipeline.memo import FileMemo, file_identity


#: What a process read of a trial sheet and its subject table, by the files' identities:
#: the validated sheet (or None when it has a problem) and each subject's row.  A batch
#: worker's steps ask for trial after trial of the same sheet (~35 ms to validate the
#: default study's sheet once, against ~13 ms for one row alone every time).
_SHEETS = FileMemo(32 * 2 ** 20)
_SUBJECTS = FileMemo(8 * 2 ** 20)


def _sheet_files(sheet, subjects) -> tuple:
    sheet_p = Path(sheet)
    return (sheet_p, Path(subjects) if subjects is not None else
            sheet_p.parent / "subjects.csv", sheet_p.parent / "study.yaml")


def trial_row(sheet, subjects, trial: str, *, check_files: bool = True) -> dict:
    """One trial's validated row, as :func:`gaitval.io.trialsheet.load_trial_row` gives
    it, from the validated sheet this process keeps (a sheet with a problem: the row
    checked alone, its problem named)."""
    from gaitval.io.trialsheet import clean_sheet, row_of

    idents = tuple(file_identity(p) for p in _sheet_files(sheet, subjects))
    key = idents if idents[0] and idents[1] else None
    clean = _SHEETS.fetch(key, lambda: clean_sheet(sheet, subjects),
                          lambda df: 0 if df is None else int(df.memory_usage(deep=True).sum()))
    row = row_of(clean, sheet, trial, check_files)
    return row if row is not None else load_trial_row(sheet, subjects, trial,
                                                     check_files=check_files)


def trial_and_subject(sheet, subjects, trial: str) -> tuple[dict, dict]:
    """One trial's validated row and its subject's, as dicts (the caller's own copies)."""
    row = trial_row(sheet, subjects, trial, check_files=False)
    path = _sheet_files(sheet, subjects)[1]
    ident = file_identity(path)
    subj = _SUBJECTS.fetch(
        None if ident is None else (ident, row["subject"]),
        lambda: load_subjects(subjects, only=row["subject"]).loc[row["subject"]].to_dict(),
        lambda _: 4096)
    return row, copy.deepcopy(subj)


def load_ingested(ingest_dir: str | Path, row: dict):
    """The ingested mocap and sensor of a trial (see :mod:`gaitval.io.ingest`)."""
    from gaitval.io.ingest import read_mocap_parquet
    d = Path(ingest_dir)
    mocap = read_mocap_parquet(d / "mocap.parquet", d / "events.csv",
                               source=row.get("mocap_path") or None, trial=row["trial"])
    if row["sensor_kind"] == "ultrasonic":
        from gaitval.io.ultrasonic import read_ultrasonic
        sensor = read_ultrasonic(d / "sensor.parquet", trial=row["trial"])
    else:
        from gaitval.io.scanlog import read_scanlog
        sensor = read_scanlog(d / "sensor.parquet", trial=row["trial"])
    return mocap, sensor
