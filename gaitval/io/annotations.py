"""Rater annotations (``*.annotations.csv``): events scored by a person from video.

Format (version 1), documented in full in ``docs/formats_recordings.md``
------------------------------------------------------------
A UTF-8 CSV file.  Leading lines starting with ``#`` are ``key: value`` metadata; the
first must be ``# gaitval-annotations v1``.  Recognised keys:

* ``time_base``: what ``t_s`` is measured on (``video``, ``mocap`` or ``sensor``);
* ``time_offset_s``: add this to ``t_s`` to get mocap time (0 when ``time_base: mocap``);
* ``rater``: default rater id; ``fps``: video frame rate (informative).

Columns (header row required; order free):

=========  ==========================================================================
``t_s``    event time in seconds on ``time_base``
``event``  ``foot_contact``, ``target_step`` or ``cross_step`` (other words are kept)
``side``   ``L`` or ``R`` (the leg the event belongs to)
``target`` target id on the mat for ``target_step`` (empty otherwise)
``value``  ``hit`` / ``miss`` for ``target_step``; ``yes`` for ``cross_step``; may be empty
``rater``  rater id (optional; defaults to the ``rater`` metadata)
=========  ==========================================================================
"""
from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

from gaitval.errors import FileFormatError
from gaitval.io.atomic import write_text
from gaitval.io.guard import loader, number

MAGIC = "# gaitval-annotations v1"
COLUMNS = ["t_s", "event", "side", "target", "value", "rater"]
KNOWN_EVENTS = ("foot_contact", "target_step", "cross_step")
SUFFIX = ".annotations.csv"


def write_annotations(path: str | Path, events: pd.DataFrame, *, time_base: str = "video",
                      time_offset_s: float = 0.0, rater: str = "R1",
                      fps: float | None = None) -> Path:
    """Write rater events (columns as in the module docstring) atomically."""
    head = [MAGIC, f"# time_base: {time_base}", f"# time_offset_s: {time_offset_s!r}",
            f"# rater: {rater}"]
    if fps is not None:
        head.append(f"# fps: {fps!r}")
    df = events.copy()
    for c in COLUMNS:
        if c not in df:
            df[c] = rater if c == "rater" else ""
    body = df[COLUMNS].to_csv(index=False, lineterminator="\n", float_format="%.4f")
    return write_text(path, "\n".join(head) + "\n" + body)




@loader("annotation file")
def read_annotations(path: str | Path, *, trial: str | None = None
                     ) -> tuple[pd.DataFrame, dict]:
    """Read an annotation file.

    Returns
    -------
    events : DataFrame
        ``t_s, event, side, target, value, rater`` plus ``t_mocap_s`` (``t_s`` +
        ``time_offset_s``).
    meta : dict
        The ``# key: value`` header.
    """
    return _read_annotations(Path(path), trial)


def _read_annotations(path: Path, trial: str | None) -> tuple[pd.DataFrame, dict]:
    if not path.is_file():
        raise FileFormatError("annotation file not found", path=path, trial=trial)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise FileFormatError(f"not UTF-8 text (byte 0x{exc.object[exc.start]:02X} at "
                              f"position {exc.start})", path=path, trial=trial,
                              hint="save it as CSV (UTF-8); see docs/formats_recordings.md") from None
    lines = text.splitlines()
    if not lines or lines[0].strip() != MAGIC:
        raise FileFormatError(f"first line must be '{MAGIC}'", path=path, trial=trial,
                              hint="see docs/formats_recordings.md")
    meta: dict[str, str] = {}
    n_head = 0
    for line in lines:
        if not line.startswith("#"):
            break
        n_head += 1
        if ":" in line and not line.startswith(MAGIC):
            k, v = line[1:].split(":", 1)
            meta[k.strip()] = v.strip()
    try:
        df = pd.read_csv(io.StringIO("\n".join(lines[n_head:])), dtype={"target": str,
                         "value": str, "side": str, "rater": str, "event": str},
                         keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise FileFormatError(f"cannot parse annotation table: {exc}", path=path,
                              trial=trial) from None
    for c in ("t_s", "event"):
        if c not in df:
            raise FileFormatError(f"annotation table has no '{c}' column", path=path,
                                  trial=trial)
    t = pd.to_numeric(df["t_s"], errors="coerce")
    bad = ~np.isfinite(t.to_numpy(dtype=np.float64, na_value=np.nan))
    if bad.any():
        row = int(np.flatnonzero(bad)[0]) + n_head + 2
        raise FileFormatError(f"t_s is not a number on line {row} "
                              f"({df['t_s'].iloc[row - n_head - 2]!r}; times must be finite)",
                              path=path, trial=trial)
    df["t_s"] = t.astype(float)
    for c in COLUMNS:
        if c not in df:
            df[c] = meta.get("rater", "") if c == "rater" else ""
    df.loc[df["rater"] == "", "rater"] = meta.get("rater", "")
    bad_side = ~df["side"].isin(["L", "R", ""])
    if bad_side.any():
        i = int(np.flatnonzero(bad_side.to_numpy())[0])
        raise FileFormatError(f"side must be L, R or empty, found {df['side'].iloc[i]!r} on "
                              f"line {i + n_head + 2}", path=path, trial=trial)
    offset = number({"time_offset_s": meta.get("time_offset_s", 0.0)}, "time_offset_s",
                    path, trial, what="annotation header")
    df["t_mocap_s"] = df["t_s"] + offset
    return df[COLUMNS + ["t_mocap_s"]], meta
