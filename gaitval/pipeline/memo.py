"""What a step read from a file, kept for the process's next step, under the file's
identity (issues 13, 38).

A batch job's worker (:mod:`gaitval.jobs.batch`) runs trial after trial of one stage, and
a trial's second verb reads what its first read (the MTST evaluation the scan log and
annotations its tracking read; every step the trial sheet).  :class:`FileMemo` keeps what
was read under the file's **identity** — resolved path, device, inode, size, and
modification and status-change times in nanoseconds — so a file rewritten in any way is
read again: gaitval replaces its outputs by renaming a new file over them (a new inode),
and an edit in place changes the times.

Entries are evicted oldest first past a byte budget.  A value handed out must not be
changed by the caller: keep immutable values, or give the caller a copy.  A process that
runs one step (``gaitval VERB`` by hand) pays one ``stat`` per read and never hits.  Only
the steps (this package) keep anything: the library they call keeps nothing between calls.
"""
from __future__ import annotations

import os
from collections import OrderedDict
from pathlib import Path
from typing import Any, Callable

def file_identity(path: str | os.PathLike) -> tuple | None:
    """``(resolved path, st_dev, st_ino, st_size, st_mtime_ns, st_ctime_ns)``, or None
    when the file cannot be stat'ed (the caller then reads it and reports the problem)."""
    try:
        p = Path(path).resolve()
        st = os.stat(p)
    except (OSError, RuntimeError, ValueError):
        return None
    return (str(p), st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns, st.st_ctime_ns)


class FileMemo:
    """Values read from files, by file identity and the reader's own options.

    ``max_bytes``: the budget; an entry's size is what the caller says it is (an entry
    larger than the budget is not kept).
    """

    def __init__(self, max_bytes: int):
        self._own = int(max_bytes)
        self._entries: OrderedDict[tuple, tuple[Any, int]] = OrderedDict()
        self._bytes = 0

    @property
    def max_bytes(self) -> int:
        """The budget."""
        return self._own

    def key(self, path: str | os.PathLike, *options) -> tuple | None:
        """The key of ``path`` read with ``options``; None: do not remember."""
        ident = file_identity(path)
        return None if ident is None else (ident, options)

    def get(self, key: tuple | None) -> Any | None:
        if key is None:
            return None
        hit = self._entries.get(key)
        if hit is None:
            return None
        self._entries.move_to_end(key)
        return hit[0]

    def put(self, key: tuple | None, value: Any, nbytes: int) -> None:
        budget = self.max_bytes
        if key is None or nbytes > budget:
            return
        old = self._entries.pop(key, None)
        if old is not None:
            self._bytes -= old[1]
        self._entries[key] = (value, int(nbytes))
        self._bytes += int(nbytes)
        while self._bytes > budget and self._entries:
            _, (_, n) = self._entries.popitem(last=False)
            self._bytes -= n

    def fetch(self, key: tuple | None, read: Callable[[], Any],
              size: Callable[[Any], int]) -> Any:
        """The value remembered under ``key``, else ``read()``, remembered as ``size(value)``
        bytes.  The value is the memo's own: copy it before handing it to code that may
        change it."""
        hit = self.get(key)
        if hit is None:
            hit = read()
            self.put(key, hit, size(hit))
        return hit
