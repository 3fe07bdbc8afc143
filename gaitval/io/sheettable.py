"""A study's CSV table (the trial sheet, the subject table) read as text and checked row by
row against its JSON schema (``workflow/schemas/*.schema.yaml``): every cell typed, every
problem collected with the file, the row (line number and id) and the column named
(:mod:`gaitval.io.trialsheet`).
"""
from __future__ import annotations

import difflib
import math
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from gaitval.configcheck import id_problem
from gaitval.errors import TrialSheetError


SCHEMA_DIR = Path(__file__).resolve().parents[2] / "workflow" / "schemas"
TRUE = {"true", "yes", "1", "y", "t"}
FALSE = {"false", "no", "0", "n", "f"}


def load_schema(name: str) -> dict:
    """Load ``workflow/schemas/<name>.schema.yaml``."""
    path = SCHEMA_DIR / f"{name}.schema.yaml"
    if not path.is_file():
        raise TrialSheetError(f"schema {path} not found; gaitval must be installed from its "
                              "source checkout (pip install -e .)")
    with open(path, encoding="utf-8") as fh:
        return yaml.safe_load(fh)


#: Id columns: each becomes a folder name under results/ and a word of a job's command.
ID_COLUMNS = ("study", "subject", "trial")
#: Whole numbers past this are typos (``repetition=1e308``), not counts.
MAX_INTEGER = 1_000_000


def _control_chars(value: str) -> list[str]:
    return sorted({repr(c) for c in value if ord(c) < 32 or ord(c) == 127})


def _coerce(value: str, spec: dict):
    """Convert one CSV cell to the schema's type; empty → None (left out of the record)."""
    v = value.strip()
    if v == "":
        return None
    t = spec.get("type")
    if t in ("number", "integer"):
        try:
            f = float(v)
        except ValueError:
            raise ValueError(f"{v!r} is not a number") from None
        if not math.isfinite(f):
            raise ValueError(f"{v!r} is not a finite number (leave the cell empty when the "
                             "value is unknown)")
        if t == "integer" and not f.is_integer():
            raise ValueError(f"{v!r} is not a whole number")
        if t == "integer" and abs(f) > MAX_INTEGER:
            raise ValueError(f"{v!r} is not a plausible count (at most {MAX_INTEGER:,})")
        return int(f) if t == "integer" else f
    if t == "boolean":
        if v.lower() in TRUE:
            return True
        if v.lower() in FALSE:
            return False
        raise ValueError(f"{v!r} is not true/false")
    return v


def _read_csv(path: Path, kind: str) -> pd.DataFrame:
    """The table as strings; TrialSheetError when it is missing or not UTF-8 CSV."""
    return _parse_csv(path, kind)


def _parse_csv(path: Path, kind: str) -> pd.DataFrame:
    try:
        if not path.is_file():
            raise TrialSheetError(f"{kind} not found", path=path)
        with warnings.catch_warnings():      # a ragged row: said by _check_ragged below
            warnings.simplefilter("ignore", pd.errors.ParserWarning)
            df = pd.read_csv(path, dtype=str, keep_default_na=False, comment=None,
                             encoding="utf-8", index_col=False)
        _check_ragged(path, kind, len(df.columns))
        return df
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError,
            ValueError) as exc:
        raise TrialSheetError(f"cannot parse {kind} as UTF-8 CSV: {exc}", path=path,
                              hint="save it as CSV (UTF-8) with a header row") from None
    except OSError as exc:
        raise TrialSheetError(f"cannot read {kind}: {exc.strerror or exc}", path=path) from None


def _check_ragged(path: Path, kind: str, n_columns: int) -> None:
    """Every row holds as many cells as the header (pandas fills missing trailing cells
    with "" and would take a short row for one with empty optional columns)."""
    import csv

    with open(path, encoding="utf-8", newline="") as fh:
        bad = [(i, len(row)) for i, row in enumerate(csv.reader(fh), start=1)
               if row and len(row) != n_columns and i > 1]
    if bad:
        rows = "; ".join(f"row {i}: {n} cells" for i, n in bad[:20])
        more = f" (and {len(bad) - 20} more)" if len(bad) > 20 else ""
        raise TrialSheetError(f"{kind} has rows whose number of cells differs from the "
                              f"header's {n_columns}: {rows}{more}", path=path,
                              hint="every row needs one cell per column (empty cells "
                              "between commas for unknown values)")


def read_table(path: Path, kind: str, schema: dict, problems: list, only: str | None = None
                ) -> tuple[pd.DataFrame, list[dict]]:
    """Rows that pass the schema as typed records (``row_line``: the row's line number);
    every problem appended to ``problems``.  ``only``: check and keep just the rows whose
    id (trial, or subject in the subject table) is this one (the header is checked all the
    same)."""
    import jsonschema

    raw = _read_csv(path, kind)
    props = schema["properties"]
    for c in raw.columns:
        close = [] if c in props else difflib.get_close_matches(c, list(props), n=1,
                                                                cutoff=0.75)
        if close:
            problems.append(TrialSheetError(f"unknown column {c!r}; did you mean "
                                            f"{close[0]!r}?", path=path))
    missing = [c for c in schema.get("required", []) if c not in raw.columns]
    if missing:
        problems.append(TrialSheetError(f"missing required column(s) {missing}", path=path))
        return raw, []
    validator = jsonschema.Draft202012Validator(schema)
    records = []
    key = "trial" if "trial" in raw.columns else "subject"
    if only is None:
        picked, rows = range(len(raw)), raw.to_dict("records")
    else:
        picked = [int(i) for i in np.flatnonzero(raw[key].str.strip().to_numpy() == only)]
        rows = raw.iloc[picked].to_dict("records")
    for i, row in zip(picked, rows):
        ident = row.get(key, "")
        safe = bool(ident) and id_problem(str(ident).strip()) is None
        shown = ident if safe else str(ident)[:40]
        where = f"row {i + 2} ({key} {shown!r})" if ident else f"row {i + 2}"  # header: 1
        trial = ident if key == "trial" and safe else None
        rec, bad = _typed_cells(row, where, trial, props, path, problems)
        ok = _schema_ok(validator, rec, bad, where, trial, path, problems)
        if ok:
            records.append({**rec, "row_line": i + 2})
    return raw, records


def _typed_cells(row: dict, where: str, trial, props: dict, path: Path, problems: list
                 ) -> tuple[dict, set]:
    """One row's cells typed by the schema's ``props`` (empty cells left out), and the
    columns with a problem (control characters, a bad id, not of the type), each appended
    to ``problems`` naming the row (``where``) and the column."""
    rec, bad = {}, set()
    for col, val in row.items():
        ctl = _control_chars(str(val))
        if ctl:
            problems.append(TrialSheetError(
                f"{where}, column {col!r}: holds control character(s) {', '.join(ctl)}",
                path=path, trial=trial))
            bad.add(col)
            continue
        if col in ID_COLUMNS and str(val).strip():
            why = id_problem(str(val).strip())
            if why:
                shown = str(val)[:40] + ("..." if len(str(val)) > 40 else "")
                problems.append(TrialSheetError(
                    f"{where}, column {col!r}: id {shown!r} {why}", path=path,
                    trial=None))
                bad.add(col)
                continue
        try:
            cv = _coerce(str(val), props.get(col, {"type": "string"}))
        except ValueError as exc:
            problems.append(TrialSheetError(f"{where}, column {col!r}: {exc}", path=path,
                                            trial=trial))
            bad.add(col)
            continue
        if cv is not None:
            rec[col] = cv
    return rec, bad


def _schema_ok(validator, rec: dict, bad: set, where: str, trial, path: Path, problems: list
               ) -> bool:
    """The typed row passes the schema and had no bad cell; each schema error appended to
    ``problems`` (a required column already said to be no number is not said again)."""
    ok = not bad
    for e in sorted(validator.iter_errors(rec), key=lambda e: list(e.path)):
        col = e.path[0] if e.path else None
        if e.validator == "required" and any(f"'{c}'" in e.message for c in bad):
            continue                                  # said already: not a number
        msg = (e.message.replace("is a required property", "is required but empty")
               if e.validator == "required" else e.message)
        colpart = f", column {col!r}" if col is not None else ""
        problems.append(TrialSheetError(f"{where}{colpart}: {msg}", path=path,
                                        trial=trial))
        ok = False
    return ok


def typed_frame(records: list[dict], schema: dict, columns: list[str]) -> pd.DataFrame:
    """The typed records as a frame: numbers float (NaN where empty), booleans bool (False
    where empty), the rest strings ("" where empty) of dtype object."""
    data = {}
    for col in columns:
        t = schema["properties"].get(col, {}).get("type")
        vals = [r.get(col) for r in records]
        if t in ("number", "integer"):
            data[col] = pd.Series([np.nan if v is None else float(v) for v in vals],
                                  dtype=float)
        elif t == "boolean":
            data[col] = pd.Series([bool(v) if isinstance(v, (bool, np.bool_)) else False
                                   for v in vals], dtype=bool)
        else:
            data[col] = pd.Series(["" if v is None or (isinstance(v, float) and np.isnan(v))
                                   else str(v) for v in vals], dtype=object)
    return pd.DataFrame(data, columns=columns)
