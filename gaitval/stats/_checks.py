"""Input checks shared by the statistics functions (one clear error, never a KeyError)."""
from __future__ import annotations

from collections.abc import Iterable, Iterator

import numpy as np
import pandas as pd

from gaitval.errors import GaitvalError


def as_by(by) -> list[str]:
    """Normalise a ``by`` argument (None, a column name or a list of names) to a list."""
    if by is None:
        return []
    if isinstance(by, str):
        return [by]
    return list(by)


def require_columns(df: pd.DataFrame, columns: Iterable[str], what: str) -> None:
    """Raise :class:`GaitvalError` naming the missing columns of ``df``."""
    if not isinstance(df, pd.DataFrame):
        raise GaitvalError(f"{what}: expected a pandas DataFrame, got {type(df).__name__}")
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise GaitvalError(
            f"{what}: column(s) {missing} not in the table",
            hint=f"available columns: {[str(c) for c in df.columns]}")


def numeric(df: pd.DataFrame, column: str, what: str) -> np.ndarray:
    """Column ``column`` as float64 (non-numbers are an error, missing values NaN)."""
    try:
        return pd.to_numeric(df[column], errors="raise").to_numpy(dtype=float)
    except (TypeError, ValueError) as exc:
        raise GaitvalError(f"{what}: column {column!r} holds non-numeric values ({exc})",
                           hint="convert the column to numbers first") from None


def groups(df: pd.DataFrame, by: list[str]) -> Iterator[tuple[dict, pd.DataFrame]]:
    """Yield ``({by column: value}, sub-frame)`` in sorted group order (whole frame if no by)."""
    if not by:
        yield {}, df
        return
    for key, sub in df.groupby(by, sort=True, dropna=False, observed=True):
        key = key if isinstance(key, tuple) else (key,)
        yield dict(zip(by, key)), sub
