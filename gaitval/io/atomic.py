"""Atomic file output.

Every file gaitval writes goes through :func:`atomic_path`: the content is written to a
temporary file in the same folder and renamed over the target only when complete, so an
interrupted run never leaves a half-written file that looks complete.  The file gets the
permissions a plain ``open(path, "w")`` would give it (``0o666`` less the umask): the
temporary file ``mkstemp`` makes is private (``0o600``), which left every report, table
and figure unreadable to other users and to a web server.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import pandas as pd


def _umask() -> int:
    """The process's umask (read without changing it where /proc allows)."""
    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


@contextlib.contextmanager
def atomic_path(path: str | Path):
    """Yield a temporary path beside ``path``; rename it over ``path`` on success.

    On an exception the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8", newline="\n")
    return Path(path)


def write_bytes(path: str | Path, data: bytes) -> Path:
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def write_parquet(df: pd.DataFrame, path: str | Path, metadata: dict[str, str] | None = None
                  ) -> Path:
    """Write a DataFrame as Parquet atomically, optionally with key/value schema metadata.

    The output is deterministic for the same frame (no pandas index, no creation time).
    """
    import pyarrow as pa

    return write_arrow(pa.Table.from_pandas(df, preserve_index=False), path, metadata)


def write_arrow(table, path: str | Path, metadata: dict[str, str] | None = None,
                dictionary: list[str] | None = None) -> Path:
    """Write a ``pyarrow.Table`` as LZ4-compressed Parquet atomically, optionally with
    key/value schema metadata.

    LZ4 rather than zstd: the default report's 127 mocap tables (19.6 million rows) are
    written in 1.8 instead of 2.6 CPU-s and read in 0.7 instead of 1.1, for 376 instead of
    311 MB (measured 2026-11-27); these are intermediate results, read back by the next
    steps.

    ``dictionary``: the only columns Parquet may dictionary-encode (default: pyarrow's
    choice, every column).  Naming the columns with few distinct values (a marker label)
    spares the writer from trying dictionaries on float columns, where they fail: the
    long marker table of a 60,000-frame trial is written in 0.07 instead of 0.12 s and
    is 15 % smaller; the values read back are the same.
    """
    import pyarrow.parquet as pq

    if metadata:
        md = dict(table.schema.metadata or {})
        md.update({k.encode(): v.encode() for k, v in metadata.items()})
        table = table.replace_schema_metadata(md)
    with atomic_path(path) as tmp:
        pq.write_table(table, tmp, compression="lz4",
                       use_dictionary=True if dictionary is None else list(dictionary))
    return Path(path)


def write_csv(df: pd.DataFrame, path: str | Path, float_format: str | None = None) -> Path:
    """Write a DataFrame as CSV atomically (no index, ``\\n`` line ends)."""
    with atomic_path(path) as tmp:
        df.to_csv(tmp, index=False, float_format=float_format, lineterminator="\n")
    return Path(path)
