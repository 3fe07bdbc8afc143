"""Shared checks of the loaders: numbers from metadata, and the last line of defence.

Every loader checks the fields it reads and raises :class:`~gaitval.errors.FileFormatError`
naming the file and the field.  :func:`loader` wraps a loader so that anything it did not
foresee (a library's own exception on a file nobody imagined) still reaches the user as a
FileFormatError naming the file, never a traceback; such an error carries
``unexpected = True`` so the fuzz harness (``tests/fuzz/``) counts it as a gap to close.
"""
from __future__ import annotations

import functools
import json
import math
from pathlib import Path
from typing import Any, Callable

from gaitval.errors import FileFormatError, GaitvalError


def loader(kind: str) -> Callable:
    """Decorator: ``f(path, *args, trial=None, **kw)`` raises only GaitvalError."""
    def deco(func: Callable) -> Callable:
        @functools.wraps(func)
        def wrapper(path, *args, **kw):
            try:
                return func(path, *args, **kw)
            except GaitvalError:
                raise
            except Exception as exc:  # noqa: BLE001 - anything else: still name the file
                err = FileFormatError(f"cannot read this {kind}: {type(exc).__name__}: "
                                      f"{str(exc)[:300]}", path=path, trial=kw.get("trial"),
                                      hint="check the file with `gaitval inspect`; if it "
                                           "looks right, please report it")
                err.unexpected = True
                raise err from None
        return wrapper
    return deco


def json_meta(raw: bytes, key: str, path: Path, trial: str | None) -> dict[str, Any]:
    """Parse a JSON metadata object; FileFormatError naming ``key`` otherwise."""
    try:
        meta = json.loads(raw)
    except (ValueError, UnicodeDecodeError) as exc:
        raise FileFormatError(f"metadata {key!r} is not valid JSON: {exc}", path=path,
                              trial=trial) from None
    if not isinstance(meta, dict):
        raise FileFormatError(f"metadata {key!r} must be a JSON object, not "
                              f"{type(meta).__name__}", path=path, trial=trial)
    return meta


def number(meta: dict, key: str, path: Path, trial: str | None, *, what: str = "metadata",
           minimum: float | None = None, above: float | None = None,
           optional: bool = False, integer: bool = False) -> float | int | None:
    """``meta[key]`` as a finite number within bounds; FileFormatError naming the field."""
    v = meta.get(key)
    if v is None:
        if optional:
            return None
        raise FileFormatError(f"{what} incomplete: field {key!r} is missing", path=path,
                              trial=trial,
                              hint="see docs/formats.md")
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        if isinstance(v, str):
            try:
                v = float(v)
            except ValueError:
                v = None
        if not isinstance(v, float):
            raise FileFormatError(f"{what} field {key!r} is {meta.get(key)!r}, not a number",
                                  path=path, trial=trial)
    v = float(v)
    bad = (not math.isfinite(v) or (minimum is not None and v < minimum)
           or (above is not None and v <= above) or (integer and not v.is_integer()))
    if bad:
        bounds = (f" >= {minimum:g}" if minimum is not None else "") + \
                 (f" > {above:g}" if above is not None else "")
        raise FileFormatError(f"{what} field {key!r} is {meta.get(key)!r}; it must be a "
                              f"finite {'whole ' if integer else ''}number{bounds}",
                              path=path, trial=trial)
    return int(v) if integer else v


def column_names(table, path: Path, trial: str | None) -> list[str]:
    """A Parquet table's column names; FileFormatError when they are not UTF-8 text."""
    try:
        return list(table.column_names)
    except UnicodeDecodeError:
        raise FileFormatError("the Parquet column names are not UTF-8 text", path=path,
                              trial=trial) from None


def text_field(meta: dict, key: str, path: Path, trial: str | None, *,
               what: str = "metadata", expected: str | None = None,
               optional: bool = True) -> str | None:
    """``meta[key]`` as text (``expected``: the one value allowed); FileFormatError naming
    the field for a number (NaN stored as a sensor name), a list or anything else."""
    v = meta.get(key)
    if v is None:
        if optional and expected is None:
            return None
        raise FileFormatError(f"{what} incomplete: field {key!r} is missing", path=path,
                              trial=trial, hint="see docs/formats.md")
    if not isinstance(v, str):
        raise FileFormatError(f"{what} field {key!r} is {v!r}, not text", path=path,
                              trial=trial)
    if expected is not None and v != expected:
        raise FileFormatError(f"{what} field {key!r} is {v!r}, expected {expected!r}",
                              path=path, trial=trial, hint="see docs/formats.md")
    return v


def version_field(meta: dict, newest: int, path: Path, trial: str | None, *,
                  what: str = "metadata") -> int:
    """``meta["version"]``: a whole number from 1 to ``newest`` (NaN, inf, 0, 1.5 and
    versions newer than this gaitval reads are refused, naming the field)."""
    v = number(meta, "version", path, trial, what=what, minimum=1, integer=True)
    if v > newest:
        raise FileFormatError(f"{what}: version {v} is newer than this gaitval reads "
                              f"({newest})", path=path, trial=trial,
                              hint="update gaitval")
    return int(v)


def column_kind(table, name: str, kinds: tuple[str, ...], path: Path,
                trial: str | None, *, what: str = "column") -> None:
    """The Parquet column ``name`` holds one of ``kinds`` ("float", "integer"); a bool,
    timestamp, text or any other type is a FileFormatError naming the column and type
    (a timestamp read as float showed 2.19e10 degC; bools turned times into 0/1)."""
    import pyarrow as pa

    typ = table.schema.field(name).type
    ok = (("float" in kinds and pa.types.is_floating(typ))
          or ("integer" in kinds and pa.types.is_integer(typ)))
    if not ok:
        raise FileFormatError(f"{what} {name!r} holds {typ}, not "
                              f"{' or '.join(k + ' numbers' for k in kinds)}", path=path,
                              trial=trial, hint="see docs/formats.md")


def enough_rows(t, minimum: int, path: Path, trial: str | None, *, what: str,
                unit: str) -> None:
    """At least ``minimum`` rows whose times advance at least once (a rate exists)."""
    import numpy as np

    n = len(t)
    if n < minimum:
        raise FileFormatError(f"{what} holds {n} {unit}{'s' if n != 1 else ''}; at least "
                              f"{minimum} are needed (a rate and a duration)", path=path,
                              trial=trial)
    d = np.diff(np.asarray(t, dtype=float))
    if n >= 2 and not np.any(d > 0):
        raise FileFormatError(f"{what}: the column 't_s' never advances over its {n} "
                              f"{unit}s (no rate)", path=path, trial=trial)
    if n >= 2 and not np.median(d) > 0:
        # the rate is 1 / the median step: a median step of 0 would be an infinite rate
        raise FileFormatError(
            f"{what}: the column 't_s' advances in only {int((d > 0).sum())} of its "
            f"{len(d)} steps (median step {float(np.median(d)):g} s), so no sampling rate "
            f"follows from it (timestamps rounded to whole seconds?)", path=path,
            trial=trial, hint="store the times with their full resolution")
