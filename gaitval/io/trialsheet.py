"""The trial sheet (``trials.csv``) and subject table (``subjects.csv``).

The trial sheet is the study manifest a lab fills in: one row per trial.  Its columns and
types are defined by the JSON schemas ``workflow/schemas/trials.schema.yaml`` and
``workflow/schemas/subjects.schema.yaml`` (documented in ``docs/formats.md``).  Paths in the
sheet are relative to the sheet's folder.

:func:`load_trial_sheet` validates every row against the schema and checks what a schema
cannot: unique trial ids, subjects present in the subject table, files that exist, a topic
for every ROS bag.  Any problem raises one :class:`~gaitval.errors.TrialSheetError` naming
the file, the row (line number and trial id) and the column.
"""
from __future__ import annotations

import difflib
from functools import lru_cache
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval.errors import TrialSheetError

SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas"
TRUE = {"true", "yes", "1", "y", "t"}
FALSE = {"false", "no", "0", "n", "f"}


@lru_cache(maxsize=None)
def load_schema(name: str) -> dict:
    """Load ``workflow/schemas/<name>.schema.yaml``."""
    path = SCHEMA_DIR / f"{name}.schema.yaml"
    if not path.is_file():
        raise TrialSheetError(f"schema {path} not found; gaitval must be installed from its "
                              "source checkout (pip install -e .)")
    with open(path, encoding="utf-8") as fh:
        return yaml.safe_load(fh)


def _coerce(value: str, spec: dict):
    """Convert one CSV cell to the schema's type; empty → None (left out of the record)."""
    v = value.strip()
    if v == "":
        return None
    t = spec.get("type")
    if t == "number":
        return float(v)
    if t == "integer":
        f = float(v)
        if not f.is_integer():
            raise ValueError(f"{v!r} is not a whole number")
        return int(f)
    if t == "boolean":
        if v.lower() in TRUE:
            return True
        if v.lower() in FALSE:
            return False
        raise ValueError(f"{v!r} is not true/false")
    return v


def _read_table(path: Path, kind: str, schema: dict) -> tuple[pd.DataFrame, list[dict]]:
    import jsonschema

    if not path.is_file():
        raise TrialSheetError(f"{kind} not found", path=path)
    try:
        raw = pd.read_csv(path, dtype=str, keep_default_na=False, comment=None)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise TrialSheetError(f"cannot parse {kind} as CSV: {exc}", path=path) from None
    props = schema["properties"]
    unknown = [c for c in raw.columns if c not in props]
    for c in unknown:
        close = difflib.get_close_matches(c, list(props), n=1, cutoff=0.75)
        if close:
            raise TrialSheetError(f"unknown column {c!r}; did you mean {close[0]!r}?",
                                  path=path)
    missing = [c for c in schema.get("required", []) if c not in raw.columns]
    if missing:
        raise TrialSheetError(f"missing required column(s) {missing}", path=path)
    validator = jsonschema.Draft202012Validator(schema)
    records = []
    key = "trial" if "trial" in raw.columns else "subject"
    for i, row in enumerate(raw.to_dict("records")):
        line = i + 2  # header is line 1
        ident = row.get(key, "")
        where = f"row {line} ({key} {ident!r})" if ident else f"row {line}"
        rec = {}
        for col, val in row.items():
            try:
                cv = _coerce(str(val), props.get(col, {"type": "string"}))
            except ValueError as exc:
                raise TrialSheetError(f"{where}, column {col!r}: {exc}", path=path,
                                      trial=ident if key == "trial" else None) from None
            if cv is not None:
                rec[col] = cv
        errors = sorted(validator.iter_errors(rec), key=lambda e: list(e.path))
        if errors:
            e = errors[0]
            col = e.path[0] if e.path else None
            if e.validator == "required":
                msg = e.message.replace("is a required property", "is required but empty")
            else:
                msg = e.message
            colpart = f", column {col!r}" if col is not None else ""
            raise TrialSheetError(f"{where}{colpart}: {msg}", path=path,
                                  trial=ident if key == "trial" else None)
        records.append(rec)
    return raw, records


def _frame(records: list[dict], schema: dict, columns: list[str]) -> pd.DataFrame:
    df = pd.DataFrame.from_records(records, columns=columns)
    for col in columns:
        t = schema["properties"].get(col, {}).get("type")
        if t in ("number", "integer"):
            df[col] = pd.to_numeric(df[col], errors="coerce").astype(float)
        elif t == "boolean":
            df[col] = df[col].map(lambda v: bool(v) if isinstance(v, (bool, np.bool_))
                                  else False).astype(bool)
        else:
            df[col] = df[col].map(lambda v: "" if v is None or (isinstance(v, float)
                                                               and np.isnan(v)) else str(v))
            df[col] = df[col].astype(object)
    return df


def load_subjects(path: str | Path) -> pd.DataFrame:
    """Read and validate a subject table; returns one row per subject (index: subject)."""
    path = Path(path)
    schema = load_schema("subjects")
    raw, records = _read_table(path, "subject table", schema)
    df = _frame(records, schema, list(raw.columns))
    dup = df["subject"][df["subject"].duplicated()]
    if len(dup):
        raise TrialSheetError(f"subject {dup.iloc[0]!r} appears more than once", path=path)
    return df.set_index("subject", drop=False)


def load_trial_sheet(path: str | Path, subjects: str | Path | None = None, *,
                     check_files: bool = True) -> pd.DataFrame:
    """Read and validate a trial sheet.

    Parameters
    ----------
    path : the trial sheet (CSV).
    subjects : the subject table; default ``subjects.csv`` beside the sheet.
    check_files : check that every referenced file exists.

    Returns
    -------
    DataFrame
        One row per trial (index: trial), every schema column present (empty string /
        NaN / False where not given), paths kept as written plus ``*_path`` columns holding
        absolute paths (``mocap_path``, ``sensor_path``, ``annotation_path``).

    Raises
    ------
    TrialSheetError
        Naming the file, row (line number and trial id) and column.
    """
    path = Path(path).resolve()
    schema = load_schema("trials")
    raw, records = _read_table(path, "trial sheet", schema)
    cols = list(dict.fromkeys(list(schema["properties"]) + list(raw.columns)))
    df = _frame(records, schema, cols)
    dup = df["trial"][df["trial"].duplicated()]
    if len(dup):
        rows = [int(i) + 2 for i in np.flatnonzero(df["trial"].to_numpy() == dup.iloc[0])]
        raise TrialSheetError(f"trial id {dup.iloc[0]!r} appears on rows {rows}; trial ids "
                              "must be unique", path=path)
    sub_path = Path(subjects) if subjects is not None else path.parent / "subjects.csv"
    subj = load_subjects(sub_path)
    base = path.parent
    for i, r in enumerate(df.itertuples(index=False)):
        where = f"row {i + 2} (trial {r.trial!r})"
        if r.subject not in subj.index:
            raise TrialSheetError(f"{where}, column 'subject': {r.subject!r} is not in the "
                                  f"subject table {sub_path}", path=path, trial=r.trial)
        is_bag = r.sensor_file.endswith(".bag") or (base / r.sensor_file).is_dir()
        if r.sensor_kind == "lrs" and is_bag and not r.sensor_topic:
            raise TrialSheetError(f"{where}, column 'sensor_topic': a ROS bag needs the "
                                  "LaserScan topic", path=path, trial=r.trial,
                                  hint="run `gaitval inspect FILE` to list the topics")
        if check_files:
            for col in ("mocap_file", "sensor_file", "annotation_file"):
                rel = getattr(r, col)
                if rel and not (base / rel).exists():
                    raise TrialSheetError(f"{where}, column {col!r}: file {rel!r} not found "
                                          f"(looked in {base})", path=path, trial=r.trial)
    for col, new in (("mocap_file", "mocap_path"), ("sensor_file", "sensor_path"),
                     ("annotation_file", "annotation_path")):
        df[new] = [str((base / v).resolve()) if v else "" for v in df[col]]
    return df.set_index("trial", drop=False)
