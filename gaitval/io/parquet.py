"""Reading back the Parquet tables gaitval writes (results, ingested data).

:func:`read_table` reads one file with :class:`pyarrow.parquet.ParquetFile` on the
calling thread: for the small files of a run (a track, a trial's ground truth, one row of
a summary) it costs about half of ``pandas.read_parquet`` (which goes through pyarrow's
dataset layer and its thread pool: 2.2 against 1.3 ms for a 800-row track).  The values
and dtypes are those of ``pandas.read_parquet`` (the same ``Table.to_pandas`` with the
pandas metadata).
"""
from __future__ import annotations

import os

import pandas as pd


def read_table(path: str | os.PathLike, columns: list[str] | None = None, *,
               pandas_metadata: bool = False):
    """The ``pyarrow.Table`` of a Parquet file (``columns``: only these).

    ``pandas_metadata``: also read the index columns the pandas metadata names (as
    ``pandas.read_parquet`` does).  Raises what pyarrow raises (OSError, ArrowInvalid):
    the callers name the file in their own error.
    """
    import pyarrow.parquet as pq

    with pq.ParquetFile(path) as pf:
        return pf.read(columns=columns, use_threads=False,
                       use_pandas_metadata=pandas_metadata)


def read_parquet(path: str | os.PathLike, columns: list[str] | None = None) -> pd.DataFrame:
    """``pandas.read_parquet(path, columns=columns)``, through :func:`read_table`."""
    return read_table(path, columns, pandas_metadata=True).to_pandas()
