"""A job's processes die with the Snakemake that runs them.

A run killed with ``kill -9`` of Snakemake alone (an out-of-memory killer, a cluster's
job killer, a user's ``kill`` of the wrong process) used to leave the batch jobs' pool
behind: its workers went on computing and writing into ``results/`` for minutes, beside
the next run.  Two guards, both cheap:

* on Linux, ``prctl(PR_SET_PDEATHSIG, SIGKILL)`` (through :mod:`ctypes`): the kernel kills
  the process the moment its parent ends (a pool worker's parent is the pool's
  forkserver, which itself ends as soon as the Snakemake that started it is gone: the
  standard library's forkserver exits when its ``alive`` pipe closes);
* everywhere, a daemon thread that checks every half second that the Snakemake process
  (its pid given, or in ``GAITVAL_RUN_PID``, which the workflow sets) is alive, and ends
  this process when it is not (a shell job's ``gaitval`` verb: its parent is the job's
  shell, which outlives Snakemake).

Nothing here runs for a ``gaitval`` verb started by hand (no ``GAITVAL_RUN_PID``).
"""
from __future__ import annotations

import os
import signal
import sys
import threading
import time

#: the environment variable naming the pid of the Snakemake running the workflow
ENV = "GAITVAL_RUN_PID"
#: seconds between two checks of the watched process
INTERVAL_S = 0.5

_watching: set[int] = set()


def alive(pid: int) -> bool:
    """Whether process ``pid`` exists and is no zombie (a killed process its parent has not
    yet reaped still answers ``kill(pid, 0)``)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except OSError:
        return False
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            state = fh.read().rsplit(b")", 1)[1].split()[0]
        return state not in (b"Z", b"X")
    except (OSError, IndexError):
        return True                      # no /proc (macOS): kill(pid, 0) said it lives


def die_with_parent() -> bool:
    """Linux: ask the kernel to SIGKILL this process when its parent ends
    (``PR_SET_PDEATHSIG``).  Returns whether it was set."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        PR_SET_PDEATHSIG = 1
        return libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def watch(pid: int | None) -> None:
    """End this process (SIGKILL to itself: no cleanup that could still write) as soon as
    process ``pid`` is gone; at once if it is gone already.  A daemon thread; nothing for
    ``pid`` None or this process itself."""
    if not pid or pid == os.getpid() or pid in _watching:
        return
    if not alive(pid):
        os.kill(os.getpid(), signal.SIGKILL)
    _watching.add(pid)

    def loop() -> None:
        while True:
            time.sleep(INTERVAL_S)
            if not alive(pid):
                os.kill(os.getpid(), signal.SIGKILL)

    threading.Thread(target=loop, name=f"gaitval-lifeline-{pid}", daemon=True).start()


def run_pid_from_env() -> int | None:
    """The Snakemake pid of ``GAITVAL_RUN_PID``, or None."""
    try:
        return int(os.environ.get(ENV, "")) or None
    except ValueError:
        return None


def pool_worker(run_pid: int) -> None:
    """A batch pool's initializer (:func:`gaitval.jobs.batch.run_batch`): die with the
    forkserver (Linux) and with the Snakemake process ``run_pid``."""
    die_with_parent()
    watch(run_pid)


def verb_process() -> None:
    """``python -m gaitval`` started by a workflow's shell job: die with its Snakemake."""
    watch(run_pid_from_env())
