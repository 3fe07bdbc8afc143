"""Reading a leg-track file (``*.tracks.csv``, ``*.tracks.parquet``) into rows in metres.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.io.tracks.exchange import (BOOL_COLUMNS, COLUMNS, PATTERNS, SIDES, UNITS, _bools,
                                        _check_meta, _columns_of, _err, _floats, _ints,
                                        _on_header_clock)


def read_tracks(path: str | Path, *, trial: str | None = None) -> tuple[pd.DataFrame, dict]:
    """Read a ``*.tracks.csv`` or ``*.tracks.parquet`` file.

    Returns
    -------
    (DataFrame, dict)
        The rows in file order, positions in metres (velocities m/s): ``t_s``, ``side``
        (``L``/``R``) or ``person``, ``x_m``, ``y_m`` and whichever of ``k``, ``vx_mps``,
        ``vy_mps``, ``observed``, ``pattern``, ``phase``, ``swing``, ``interpolated`` the
        file has; and the header (``format, version, units, frame, clock``, and any other
        key, e.g. ``source``).  Times are on the header's clock: as stored, plus the
        header's ``clock_offset_s`` when it gives one (a tracker on a third clock).

    Raises
    ------
    FileFormatError
        Naming the file, the field or column, and the row (CSV: the file's line;
        Parquet: the data row, 1-based): a wrong format line or version, units other than
        ``m``/``mm``, an unknown frame or clock, a missing column, a non-number, a side
        other than L/R, a leg missing at a time stamp, a time stamp given twice.
    """
    p = Path(path)
    meta, names, cols, where, meta_lines, first_line = _columns_of(p, trial, "tracks")
    meta = _check_meta(meta, p, trial, meta_lines)
    _check_names(p, names, trial)
    n = len(cols["t_s"])
    if n == 0:
        raise _err(p, "no rows", trial)
    out = {"t_s": _on_header_clock(_floats(p, "t_s", cols["t_s"], where, trial,
                                           finite=True), meta)}
    if "k" in names:
        out["k"] = _ints(p, "k", cols["k"], where, trial, 0, 2 ** 62)
    key = "side" if "side" in names else "person"
    ids = _ids(p, key, cols, where, trial)
    out[key] = pd.Series(ids, dtype=object)
    out.update(_optional_columns(p, names, cols, where, trial, UNITS[meta["units"]]))
    df = pd.DataFrame(out)
    _check_rows(df, p, key, ids, where, trial)
    df.attrs = {}
    # where a row is in the file, for later errors (tracks_to_sensor): CSV lines or
    # Parquet data rows, in the order of the rows returned
    meta["_row"] = ("line", first_line) if meta_lines is not None else ("row", 1)
    return df, meta


def _check_names(p: Path, names, trial) -> None:
    """The columns of a track file: known, ``t_s``, ``x``, ``y``, and ``side`` or
    ``person``."""
    unknown = [n for n in names if n not in COLUMNS]
    if unknown:
        raise _err(p, f"unknown column(s) {', '.join(map(repr, unknown))}", trial,
                   hint=f"the columns are {', '.join(COLUMNS)}")
    for c in ("t_s", "x", "y"):
        if c not in names:
            raise _err(p, f"column {c!r} is missing", trial)
    if ("side" in names) == ("person" in names):
        raise _err(p, "exactly one of the columns 'side' (legs) and 'person' (people) "
                   "is needed", trial)


def _ids(p: Path, key: str, cols: dict, where, trial) -> list[str]:
    """The ``side`` (L or R) or ``person`` (not empty) of each row."""
    ids = ["" if v is None else str(v).strip() for v in cols[key]]
    for i, v in enumerate(ids):
        if key == "side" and v not in SIDES:
            raise _err(p, f"column 'side', {where(i)}: {cols[key][i]!r} is not L or R",
                       trial)
        if key == "person" and not v:
            raise _err(p, f"column 'person', {where(i)}: empty person id", trial)
    return ids


def _optional_columns(p: Path, names, cols: dict, where, trial, scale: float) -> dict:
    """Positions and velocities in metres (``scale``: the header's units), the flags, the
    leg pattern and the phase, each as the file gives it."""
    out = {}
    for c, name in (("x", "x_m"), ("y", "y_m"), ("vx", "vx_mps"), ("vy", "vy_mps")):
        if c in names:
            v = _floats(p, c, cols[c], where, trial, finite=False)
            out[name] = v * scale if scale != 1.0 else v
    for c in BOOL_COLUMNS:
        if c in names:
            out[c] = _bools(p, c, cols[c], where, trial)
    if "pattern" in names:
        pat = ["" if v is None or (isinstance(v, float) and np.isnan(v)) else str(v).strip()
               for v in cols["pattern"]]
        for i, v in enumerate(pat):
            if v not in PATTERNS:
                raise _err(p, f"column 'pattern', {where(i)}: {v!r} is not one of "
                           f"{', '.join(x for x in PATTERNS if x)} or empty", trial)
        out["pattern"] = pd.Series(pat, dtype=object)
    if "phase" in names:
        out["phase"] = _ints(p, "phase", cols["phase"], where, trial, -1, 5)
    return out


def _check_rows(df: pd.DataFrame, p: Path, key: str, ids: list[str], where, trial) -> None:
    """No time stamp with one leg or person twice; a leg file has both legs at every
    time stamp."""
    dup = df.duplicated(["t_s", key])
    if dup.any():
        i = int(np.flatnonzero(dup.to_numpy())[0])
        raise _err(p, f"{where(i)}: time stamp {float(df['t_s'].iloc[i])!r} s has {key} "
                   f"{ids[i]!r} twice", trial)
    if key == "side":
        for s in SIDES:
            if not (df["side"] == s).any():
                raise _err(p, f"column 'side': leg {s} is missing (no row has side {s})",
                           trial, hint="a leg track file has rows for both legs; a tracker "
                           "that gives only people uses the column 'person'")
        counts = df.groupby("t_s", sort=False)["side"].transform("size")
        if (counts < 2).any():
            i = int(np.flatnonzero((counts < 2).to_numpy())[0])
            other = "R" if ids[i] == "L" else "L"
            raise _err(p, f"{where(i)}: leg {other} is missing at time stamp "
                       f"{float(df['t_s'].iloc[i])!r} s (every time stamp has one row per leg; "
                       "write x, y empty where a leg has no track)", trial)
