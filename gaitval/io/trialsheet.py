"""The trial sheet (``trials.csv``) and subject table (``subjects.csv``).

The trial sheet is the study manifest a lab fills in: one row per trial.  Its columns and
types are defined by the JSON schemas ``workflow/schemas/trials.schema.yaml`` and
``workflow/schemas/subjects.schema.yaml`` (documented in ``docs/formats.md``).  Paths in the
sheet are relative to the sheet's folder and must stay inside it, unless the study allows
others (``allow_outside_paths: true`` in the ``study.yaml`` beside the sheet, or the
``allow_outside_paths`` argument): a sheet cannot make gaitval read ``../../etc/passwd``.

:func:`sheet_problems` validates every row against the schema and checks what a schema
cannot: finite numbers, unique trial ids, subjects present in the subject table, files
that exist and stay inside the sheet's folder, a sensor file that fits the sensor kind, a
topic for every ROS bag.  It returns *every* problem (``gaitval validate`` lists them all);
:func:`load_trial_sheet` raises them as one :class:`~gaitval.errors.TrialSheetError`, each
naming the file, the row (line number and trial id) and the column.

Every call reads and validates the files again (nothing is kept between calls): a caller
that asks for many trials' rows keeps the validated sheet itself (:func:`clean_sheet`,
:func:`row_of`; :func:`gaitval.pipeline.steps.trials.trial_row`).
"""
from __future__ import annotations

import copy
import logging
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval.configcheck import path_value_problem
from gaitval.errors import GaitvalError, TrialSheetError
from gaitval.io.sheettable import load_schema, read_table, typed_frame


log = logging.getLogger("gaitval.io.trialsheet")


_YAML_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)   # libyaml when built with it


def _subject_problems(path: Path, problems: list, only: str | None = None) -> pd.DataFrame:
    """The subject table's valid rows (index: subject; ``attrs['all_ids']``: every subject
    named), its problems appended to ``problems``."""
    return _subject_frame(path, problems, only)


def _subject_frame(path: Path, problems: list, only: str | None) -> pd.DataFrame:
    schema = load_schema("subjects")
    raw, records = read_table(path, "subject table", schema, problems, only)
    cols = list(dict.fromkeys(["subject"] + list(raw.columns)))   # as the file has them
    df = typed_frame(records, schema, cols + ["row_line"])
    for subject, rows in df.groupby("subject", sort=False)["row_line"]:
        if len(rows) > 1:
            problems.append(TrialSheetError(f"subject {subject!r} appears on rows "
                                            f"{[int(r) for r in rows]}", path=path))
    df = df.drop_duplicates("subject").set_index("subject", drop=False)
    # subjects on rows with a problem still exist: the sheet's rows need not say so again
    df.attrs["all_ids"] = set(raw["subject"]) if "subject" in raw.columns else set(df.index)
    return df


def load_subjects(path: str | Path, only: str | None = None) -> pd.DataFrame:
    """Read and validate a subject table; returns one row per subject (index: subject).

    ``only``: read and validate just that subject's row (the header all the same).

    Raises
    ------
    TrialSheetError
        Every problem found, each naming the row and column.
    """
    problems: list[GaitvalError] = []
    df = _subject_problems(Path(path), problems, only)   # remembered there when valid
    raise_all(problems)
    return df.drop(columns="row_line")


def raise_all(problems: list[GaitvalError]) -> None:
    """Raise the problems as one TrialSheetError (the first's file; one line each)."""
    if len(problems) == 1:
        raise problems[0]
    if problems:
        lines = "\n".join(f"  - {p.problem}" for p in problems)
        raise TrialSheetError(f"{len(problems)} problems:\n{lines}", path=problems[0].path)


def _allows_outside(sheet: Path) -> bool:
    """``allow_outside_paths: true`` in the study.yaml beside the sheet."""
    return _read_allows_outside(sheet.parent / "study.yaml")


def _read_allows_outside(cal: Path) -> bool:
    try:
        with open(cal, encoding="utf-8") as fh:
            study = yaml.load(fh, Loader=_YAML_LOADER)
    except (OSError, yaml.YAMLError, UnicodeDecodeError):
        return False
    return isinstance(study, dict) and study.get("allow_outside_paths") is True


def sheet_problems(path: str | Path, subjects: str | Path | None = None, *,
                   check_files: bool = True, allow_outside_paths: bool | None = None,
                   only: str | None = None) -> tuple[pd.DataFrame, list[GaitvalError]]:
    """Every problem of a trial sheet and its subject table, and the rows that passed.

    Parameters are those of :func:`load_trial_sheet`.  Returns ``(frame, problems)``;
    ``frame`` holds the rows without a schema problem (index: trial).  ``only``: just that
    trial's rows (and the subject table's header and rows), for a job that runs one trial:
    the other rows' problems are the whole-sheet check's (``gaitval validate``, the
    workflow's start), and checking 100s of rows costs ~0.3 s per job.
    """
    path = Path(path).resolve()
    problems: list[GaitvalError] = []
    schema = load_schema("trials")
    raw, records = read_table(path, "trial sheet", schema, problems, only)
    if raw.empty and "trial" in raw.columns:
        problems.append(TrialSheetError("the trial sheet has a header but no trials",
                                        path=path, hint="add one row per trial"))
    cols = list(dict.fromkeys(list(schema["properties"]) + list(raw.columns)))
    df = typed_frame(records, schema, cols + ["row_line"])
    for trial, rows in df.groupby("trial", sort=False)["row_line"]:
        if len(rows) > 1:
            problems.append(TrialSheetError(f"trial id {trial!r} appears on rows "
                                            f"{[int(r) for r in rows]}; trial ids must be "
                                            "unique", path=path, trial=trial))
    # ids that differ only in case name one folder on macOS and Windows
    folded = df.assign(_key=df["trial"].astype(str).str.lower()).drop_duplicates("trial")
    for _, grp in folded.groupby("_key", sort=False):
        if len(grp) > 1:
            ids = [str(t) for t in grp["trial"]]
            problems.append(TrialSheetError(
                f"trial ids {', '.join(repr(t) for t in ids)} (rows "
                f"{[int(r) for r in grp['row_line']]}) differ only in case; their folders "
                "would be one on macOS and Windows", path=path, trial=ids[0],
                hint="give each trial an id that differs in more than case"))
    if only is None:
        _warn_reused_recordings(df, path)
    sub_path = Path(subjects) if subjects is not None else path.parent / "subjects.csv"
    sub_only = None if only is None else next((r["subject"] for r in records
                                                if "subject" in r), "")
    try:
        subj = _subject_problems(sub_path, problems, sub_only)
    except TrialSheetError as exc:
        problems.append(exc)
        subj = None
    if allow_outside_paths is None:
        allow_outside_paths = _allows_outside(path)
    for r in df.itertuples(index=False):
        _row_problems(r, path, subj, sub_path, check_files, allow_outside_paths, problems)
    for col, new in (("mocap_file", "mocap_path"), ("sensor_file", "sensor_path"),
                     ("annotation_file", "annotation_path")):
        df[new] = [_absolute(path.parent, v) for v in df[col]]
    df = df.drop_duplicates("trial")
    row_lines = dict(zip(df["trial"], (int(x) for x in df["row_line"])))
    df = df.drop(columns="row_line").set_index("trial", drop=False)
    df.attrs["row_lines"] = row_lines          # the sheet's line of each trial
    return df, problems


def _absolute(base: Path, rel: str) -> str:
    if not rel:
        return ""
    try:
        return str((base / rel).resolve())
    except (OSError, RuntimeError, ValueError):
        return str(base / rel)


#: A hand-measured laser position farther than this from the mocap origin (metres) is no
#: room's: the largest gait laboratories and motion-capture halls span a few tens of metres,
#: while a position typed in millimetres is hundreds to thousands.
MAX_ROOM_M = 50.0

_SENSOR_SUFFIXES = {"ultrasonic": (".us.parquet",),
                    "lrs": (".scan.parquet", ".bag", ".db3", ".mcap", "")}


def _row_problems(r, sheet: Path, subj, sub_path: Path, check_files: bool,
                  allow_outside: bool, problems: list) -> None:
    """What a schema cannot check about one row (appended to ``problems``)."""
    base, where = sheet.parent, f"row {r.row_line} (trial {r.trial!r})"

    def add(col: str, problem: str, hint: str | None = None):
        problems.append(TrialSheetError(f"{where}, column {col!r}: {problem}", path=sheet,
                                        trial=r.trial, hint=hint))

    if not r.mocap_file and not (r.annotation_file or r.annotation_topic):
        add("mocap_file", "is required but empty (a trial without motion capture needs hand "
            "annotations: annotation_file or annotation_topic)")
    if subj is not None and r.subject not in subj.attrs.get("all_ids", subj.index):
        add("subject", f"{r.subject!r} is not in the subject table {sub_path}")
    for col in ("mocap_file", "sensor_file", "annotation_file"):
        rel = getattr(r, col)
        if rel:
            _path_problem(base, rel, col, check_files, allow_outside, add)
    name = r.sensor_file.lower()
    if r.sensor_file and not any(name.endswith(x) for x in _SENSOR_SUFFIXES[r.sensor_kind]
                                 if x) and not _is_dir(base / r.sensor_file):
        add("sensor_file", f"{r.sensor_file!r} is not a {r.sensor_kind} log (expected "
            f"{', '.join(x for x in _SENSOR_SUFFIXES[r.sensor_kind] if x)}"
            f"{' or a ROS 2 bag folder' if r.sensor_kind == 'lrs' else ''})")
    lo, hi = getattr(r, "sector_min_deg", np.nan), getattr(r, "sector_max_deg", np.nan)
    if np.isnan(lo) != np.isnan(hi):
        add("sector_min_deg" if np.isnan(lo) else "sector_max_deg",
            "is empty while the other sector bound is set (give both, or neither)")
    elif not np.isnan(lo) and lo >= hi:
        add("sector_max_deg", f"{hi:g} is not above sector_min_deg {lo:g}")
    pose = [getattr(r, c, np.nan) for c in ("sensor_x_m", "sensor_y_m", "sensor_yaw_deg")]
    if any(np.isnan(pose)) and not all(np.isnan(pose)):
        empty = [c for c, v in zip(("sensor_x_m", "sensor_y_m", "sensor_yaw_deg"), pose)
                 if np.isnan(v)]
        add(empty[0], "is empty while other cells of the hand-measured sensor pose are set "
            "(give sensor_x_m, sensor_y_m and sensor_yaw_deg, or none)")
    is_bag = name.endswith(".bag") or _is_dir(base / r.sensor_file)
    if r.sensor_kind == "lrs" and is_bag and not r.sensor_topic:
        add("sensor_topic", "a ROS bag needs the LaserScan topic",
            "run `gaitval inspect FILE` to list the topics")


def _is_dir(p: Path) -> bool:
    try:
        return p.is_dir()
    except (OSError, ValueError):
        return False


def _warn_reused_recordings(df: pd.DataFrame, path: Path) -> None:
    """A warning for each recording (mocap or sensor file) that several rows name: a sheet
    has no time windows, so such rows analyse the same data again and count it as more
    trials (a copy-paste error, usually)."""
    for col in ("mocap_file", "sensor_file"):
        if col not in df:
            continue
        named = df[[col, "row_line"]][df[col].astype(str).str.strip() != ""]
        for f, rows in named.groupby(col, sort=True)["row_line"]:
            if len(rows) > 1:
                lines = [int(r) for r in rows]
                log.warning("%s: %s %r is named by %d rows (%s); each analyses the same "
                            "recording again and counts as a trial of its own", path, col,
                            f, len(lines), ", ".join(map(str, lines[:10]))
                            + (", ..." if len(lines) > 10 else ""))


def _path_problem(base: Path, rel: str, col: str, check_files: bool, allow_outside: bool,
                  add) -> None:
    """A path that is too long, leaves the sheet's folder, holds a brace (Snakemake reads
    ``{...}`` in an input's path as a wildcard), or names no file."""
    why = path_value_problem(rel)
    if why and "brace" in why:
        add(col, f"path {rel[:60]!r}{'...' if len(rel) > 60 else ''} {why}; rename the file")
        return
    try:
        target = (base / rel).resolve()
        inside = target.is_relative_to(base.resolve())
        exists = target.exists()
    except (OSError, RuntimeError, ValueError) as exc:
        add(col, f"path {rel[:60]!r}{'...' if len(rel) > 60 else ''} cannot be used: "
            f"{getattr(exc, 'strerror', None) or exc}")
        return
    if not inside and not allow_outside:
        add(col, f"path {rel!r} leads outside the trial sheet's folder {base}",
            "put the files beside the sheet, or set allow_outside_paths: true in the "
            "study.yaml beside it (docs/formats.md)")
    elif check_files and not exists:
        add(col, f"file {rel!r} not found (looked in {base})")


def load_trial_sheet(path: str | Path, subjects: str | Path | None = None, *,
                     check_files: bool = True, allow_outside_paths: bool | None = None
                     ) -> pd.DataFrame:
    """Read and validate a trial sheet.

    Parameters
    ----------
    path : the trial sheet (CSV).
    subjects : the subject table; default ``subjects.csv`` beside the sheet.
    check_files : check that every referenced file exists.
    allow_outside_paths : accept paths that leave the sheet's folder (absolute paths,
        ``../``); None: as the ``study.yaml`` beside the sheet says (default: no).

    Returns
    -------
    DataFrame
        One row per trial (index: trial), every schema column present (empty string /
        NaN / False where not given), paths kept as written plus ``*_path`` columns holding
        absolute paths (``mocap_path``, ``sensor_path``, ``annotation_path``).

    Raises
    ------
    TrialSheetError
        Every problem found, each naming the file, row (line number and trial id) and
        column.
    """
    df, problems = sheet_problems(path, subjects, check_files=check_files,
                                  allow_outside_paths=allow_outside_paths)
    raise_all(problems)
    return df


def _row_of_clean_sheet(path, subjects, trial: str, check_files: bool) -> dict | None:
    """``trial``'s row when the whole sheet, its subject table and study.yaml have no
    problem (:func:`clean_sheet`) and, with ``check_files``, the row's files exist; else
    None, and :func:`load_trial_row` checks the row alone and names its problems."""
    return row_of(clean_sheet(path, subjects), path, trial, check_files)


def clean_sheet(path, subjects) -> pd.DataFrame | None:
    """The validated sheet (:func:`sheet_problems`, its files not checked) when it, its
    subject table and study.yaml have no problem, else None.  ~35 ms for the default
    study's 127 rows: a caller asking for many trials' rows keeps it
    (:func:`gaitval.pipeline.steps.trials.trial_and_subject`) and picks them with
    :func:`row_of`."""
    df, problems = sheet_problems(Path(path).resolve(), subjects, check_files=False)
    return None if problems else df


def row_of(clean: pd.DataFrame | None, path, trial: str, check_files: bool) -> dict | None:
    """``trial``'s row of a :func:`clean_sheet` (a copy), None when there is none or, with
    ``check_files``, one of its files is missing."""
    sheet = Path(path).resolve()
    if clean is None or trial not in clean.index:
        return None
    row = copy.deepcopy(clean.loc[trial].to_dict())
    if check_files:
        for col in ("mocap_file", "sensor_file", "annotation_file"):
            if row[col] and not _exists(sheet.parent / row[col]):
                return None
    return row


def _exists(p: Path) -> bool:
    try:
        return p.resolve().exists()
    except (OSError, RuntimeError, ValueError):
        return False


def load_trial_row(path: str | Path, subjects: str | Path | None, trial: str, *,
                   check_files: bool = True) -> dict:
    """One trial's validated row, as a dict (the columns of :func:`load_trial_sheet`).

    Only that row, its subject's row and the two headers are validated: the whole sheet
    is checked once by ``gaitval validate`` and at the workflow's start, and checking its
    100s of rows again would cost every per-trial job ~0.3 s.

    Raises
    ------
    TrialSheetError
        A problem of the row, its subject or a header; or the trial is not in the sheet.
    """
    row = _row_of_clean_sheet(path, subjects, trial, check_files)
    if row is not None:
        return row
    df, problems = sheet_problems(path, subjects, check_files=check_files, only=trial)
    raise_all(problems)
    if trial not in df.index:
        raise TrialSheetError(f"trial {trial!r} is not in the trial sheet", path=path,
                              trial=trial)
    return df.loc[trial].to_dict()


def sheet_warnings(df: pd.DataFrame) -> list[str]:
    """What a sheet holds that is legal but probably a mistake, for ``gaitval validate`` to
    print beside its problems (the run's registration check refuses the trials that the
    mistake actually breaks: :mod:`gaitval.registration.plausibility`).

    * a hand-measured position more than :data:`MAX_ROOM_M` from the mocap origin:
      millimetres look like metres;
    * every hand-measured yaw within +-2 pi, not all zero: degrees look like radians (a laser
      aligned with the mocap axes gives 0 or about +-90, +-180 degrees, rarely all below 6.3).
    """
    out = []
    for col in ("sensor_x_m", "sensor_y_m"):
        v = pd.to_numeric(df[col], errors="coerce") if col in df else pd.Series(dtype=float)
        for trial, x in v[v.abs() > MAX_ROOM_M].items():
            out.append(f"trial {trial!r}, column {col!r}: {x:g} m puts the laser beyond any "
                       f"motion-capture room (more than {MAX_ROOM_M:g} m from the mocap "
                       "origin): millimetres typed as metres? (the run refuses the trial "
                       "if its legs then land outside the laser's view)")
    if "sensor_yaw_deg" in df:
        yaw = pd.to_numeric(df["sensor_yaw_deg"], errors="coerce").dropna()
        if len(yaw) and (yaw.abs() <= 2 * np.pi).all() and (yaw != 0).any():
            out.append(f"every sensor_yaw_deg lies within +-2 pi ({yaw.min():g} .. "
                       f"{yaw.max():g}): degrees typed as radians? (the column is in "
                       "degrees; the run refuses a trial whose legs then land outside the "
                       "laser's view)")
    return out
