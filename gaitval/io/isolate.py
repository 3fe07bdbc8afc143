"""Run a native library call in a child process, so its crash or hang is an error, not ours.

ezc3d [1]_ is C++: a file it does not expect can end the interpreter with a segmentation
fault or keep it in a loop, and no ``try`` catches either.  :func:`run_isolated` forks, runs
the call in the child, sends the (picklable) result back through a pipe and turns the
child's death by a signal, a silent exit or a time-out into a
:class:`~gaitval.errors.FileFormatError` that names the file.  Where ``os.fork`` does not
exist (Windows) the call runs in-process; gaitval's own checks before the call
(:mod:`gaitval.io.c3d_format`) are then the only protection.

References
----------
.. [1] Michaud, B., & Begon, M. (2021). ezc3d: An easy C3D file I/O cross-platform
   solution for C++, Python and MATLAB. Journal of Open Source Software, 6(58), 2911.
"""
from __future__ import annotations

import os
import pickle
import select
import signal
import time
from pathlib import Path
from typing import Any, Callable

from gaitval.errors import FileFormatError


#: Objects a call in the child asked to keep (:func:`keep_until_exit`); True in a child.
_KEPT: list = []
_IN_CHILD = False


def keep_until_exit(obj: Any) -> None:
    """In the child of :func:`run_isolated`, keep ``obj`` alive until the child's
    ``os._exit``, which frees it with the rest of the process instead of object by object
    (an ezc3d object of a 60,000-frame trial takes ~0.04 s to destroy).  Outside a child
    (the in-process fallback) nothing is kept."""
    if _IN_CHILD:
        _KEPT.append(obj)


class ChildError(Exception):
    """An exception raised inside the child, carried back as (type name, message)."""

    def __init__(self, type_name: str, message: str):
        super().__init__(message)
        self.type_name = type_name


def _signal_name(sig: int) -> str:
    try:
        return signal.Signals(sig).name
    except ValueError:
        return f"signal {sig}"


def run_isolated(func: Callable[..., Any], *args: Any, path: str | Path, trial: str | None,
                 what: str, timeout_s: float, memory_bytes: int | None = None) -> Any:
    """``func(*args)`` in a forked child; its result, or an error naming ``path``.

    Parameters
    ----------
    func, args
        The call; its result must be picklable.
    path, trial
        Named in the error.
    what : str
        Who does the work, for the message (``"ezc3d"``).
    timeout_s : float
        Longest time the child may take.
    memory_bytes : int, optional
        Address space the child may add to the parent's (``RLIMIT_AS`` in the child, never
        above an inherited limit): an allocation beyond it fails there (``MemoryError``,
        ``std::bad_alloc``) instead of swapping the machine.

    Raises
    ------
    ChildError
        ``func`` raised an exception in the child (type name and message kept).
    FileFormatError
        The child died from a signal (segmentation fault, abort), exited without a result,
        or did not finish within ``timeout_s``.
    """
    if not hasattr(os, "fork"):
        return func(*args)
    rfd, wfd = os.pipe()
    pid = os.fork()
    if pid == 0:                                                    # the child
        os.close(rfd)
        _child(func, args, wfd, memory_bytes)
    os.close(wfd)
    try:
        data, timed_out = _collect(rfd, timeout_s)
    finally:
        os.close(rfd)
    if timed_out:
        os.kill(pid, signal.SIGKILL)
    _, status = os.waitpid(pid, 0)
    if timed_out:
        raise FileFormatError(f"{what} did not finish reading it within {timeout_s:.0f} s "
                              "(the file makes it loop)", path=path, trial=trial,
                              hint="re-export the file from the capture software")
    if os.WIFSIGNALED(status):
        raise FileFormatError(f"{what} crashed reading it ({_signal_name(os.WTERMSIG(status))})"
                              "; the file is corrupt in a way gaitval's checks did not "
                              "catch", path=path, trial=trial,
                              hint="re-export the file from the capture software, and "
                                   "please report the file to gaitval")
    try:
        kind, payload = pickle.loads(data)
    except Exception:                       # noqa: BLE001 - an empty or cut-off answer
        raise FileFormatError(f"{what} ended without an answer (exit status "
                              f"{os.waitstatus_to_exitcode(status)})", path=path,
                              trial=trial) from None
    if kind == "error":
        raise ChildError(*payload)
    return payload


def _limit_memory(extra_bytes: int) -> None:
    """``RLIMIT_AS`` = this process's virtual size + ``extra_bytes`` (not above the
    inherited limit).  Without ``/proc`` (macOS, which does not enforce ``RLIMIT_AS``
    anyway) the virtual size is unknown and nothing is limited."""
    import resource

    try:
        with open("/proc/self/status", encoding="ascii") as fh:
            vm = next((int(line.split()[1]) * 1024 for line in fh
                       if line.startswith("VmSize:")), 0)
    except OSError:
        return
    if not vm:
        return
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    want = vm + int(extra_bytes)
    for lim in (soft, hard):
        if lim != resource.RLIM_INFINITY:
            want = min(want, lim)
    try:
        resource.setrlimit(resource.RLIMIT_AS, (want, hard))
    except (ValueError, OSError):                      # a platform without RLIMIT_AS
        pass


def _child(func, args, wfd: int, memory_bytes: int | None = None) -> None:
    """Body of the child: run, pickle, write, and leave without running parent clean-ups."""
    global _IN_CHILD
    _IN_CHILD = True
    code = 0
    try:
        import faulthandler
        faulthandler.disable()          # the parent reports a crash; no dump on its stderr
        if memory_bytes is not None:
            _limit_memory(memory_bytes)
        try:
            out = ("ok", func(*args))
        except BaseException as exc:       # noqa: BLE001 - carried to the parent
            out = ("error", (type(exc).__name__, str(exc)))
        data = pickle.dumps(out, protocol=pickle.HIGHEST_PROTOCOL)
        view = memoryview(data)
        while view:
            view = view[os.write(wfd, view):]
    except BaseException:                  # noqa: BLE001
        code = 3
    finally:
        os._exit(code)


def _collect(rfd: int, timeout_s: float) -> tuple[bytes, bool]:
    """Read the pipe to its end; (data, True) when ``timeout_s`` ran out first."""
    chunks, deadline = [], time.monotonic() + timeout_s
    while True:
        left = deadline - time.monotonic()
        if left <= 0:
            return b"", True
        ready, _, _ = select.select([rfd], [], [], left)
        if not ready:
            continue
        chunk = os.read(rfd, 1 << 20)
        if not chunk:
            return b"".join(chunks), False
        chunks.append(chunk)
