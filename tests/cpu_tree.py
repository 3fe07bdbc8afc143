"""CPU time of a command and of every process it starts, killed runs' orphans included.

    python3 tests/cpu_tree.py .venv/bin/python -m pytest -n 0 -q tests/test_resume.py

``/usr/bin/time`` counts only the descendants that their parents waited for: the kill
test's (tests/test_resume.py) killed process groups leave their job processes to init, and
their CPU is lost.  Here the command runs under a child subreaper (Linux
``PR_SET_CHILD_SUBREAPER``): orphaned descendants are reparented to this process, which
reaps them all, so ``RUSAGE_CHILDREN`` holds the whole tree's user and system CPU.  The
suite's cost is measured this way (the machine is shared: wall time says little)."""
from __future__ import annotations

import ctypes
import os
import resource
import sys
import time

PR_SET_CHILD_SUBREAPER = 36


def main(argv: list[str]) -> int:
    ctypes.CDLL(None).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    t0 = time.monotonic()
    pid = os.fork()
    if pid == 0:
        os.execvp(argv[0], argv)
    rc = None
    while True:
        try:
            p, status = os.wait()
        except ChildProcessError:
            break
        if p == pid:
            rc = os.waitstatus_to_exitcode(status)
    ru = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"CPU user {ru.ru_utime:.1f} s sys {ru.ru_stime:.1f} s total "
          f"{ru.ru_utime + ru.ru_stime:.1f} s; wall {time.monotonic() - t0:.0f} s; exit {rc}",
          flush=True)
    return rc or 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
