"""A warm process for many short ``gaitval`` jobs: import once, fork per job (issue 13).

A local workflow run is hundreds of short jobs (ingest, register, track, evaluate per
trial).  Started as ``python -m gaitval VERB ...`` each one spends 0.7–1.9 CPU-s importing
numpy, pandas, pyarrow, scipy and gaitval before ~0.1–0.6 s of work.  The fork server
imports all of that once; each job is then a ``fork()`` of it (copy-on-write, a few
milliseconds) that runs ``gaitval.cli.main(args)`` — the same function, the same arguments,
the same files as the plain command, so outputs are byte-identical.  Snakemake still sees one
job per trial (its DAG, reruns and logs are unchanged); on a cluster, where no server runs,
:mod:`gaitval.forkclient` falls back to the plain command.

Lifecycle (``Snakefile``: ``onstart`` / ``onsuccess`` / ``onerror`` when the config's
``fork_server`` is true): started with the Snakemake process's pid as ``--owner``; it exits
when that process is gone (a killed run leaves no server behind), on SIGTERM, or on SIGINT,
and removes its socket.  The socket lives in a private directory (mode 0700) under the
temporary directory, so only the same user can submit jobs.

Protocol (Unix stream socket): the client sends a 4-byte length and a JSON object
``{"argv", "cwd", "env"}`` with its stdin/stdout/stderr attached (SCM_RIGHTS); the server
forks; the child (leader of its own process group) answers its pid (4 bytes), runs the
verb with those descriptors, working directory and environment, and answers the exit
code (4 bytes).  A child whose client
disconnects before the end (the job was cancelled) exits at once.

Usage::

    python -m gaitval.forkserver --socket PATH --owner PID
"""
from __future__ import annotations

import argparse
import gc
import importlib
import marshal
import os
import pkgutil
import signal
import socket
import struct
import sys
import threading
import time
import traceback

# Imported lazily by some verbs; warm them too (optional ones may be absent).
THIRD_PARTY = ("numpy", "pandas", "pyarrow", "pyarrow.parquet", "pyarrow.csv", "scipy.signal",
               "scipy.stats", "scipy.optimize", "scipy.interpolate", "scipy.linalg",
               "scipy.spatial", "matplotlib.pyplot", "ezc3d", "jinja2", "yaml",
               "sklearn.cluster", "sklearn.mixture", "motmetrics", "rosbags.highlevel",
               "jsonschema")
SKIP = {"gaitval.__main__", "gaitval.forkserver", "gaitval.forkclient"}


def preload() -> list[str]:
    """Import gaitval's modules and the libraries its verbs use; the names that failed."""
    failed = []
    import matplotlib
    matplotlib.use("Agg")
    for name in THIRD_PARTY:
        try:
            importlib.import_module(name)
        except Exception:                      # optional or broken: the job will say so
            failed.append(name)
    import gaitval
    for mod in pkgutil.walk_packages(gaitval.__path__, "gaitval."):
        if mod.name in SKIP:
            continue
        try:
            importlib.import_module(mod.name)
        except Exception:
            failed.append(mod.name)
    try:                                       # parsed once here instead of in every job
        from gaitval.io.trialsheet import load_schema
        for name in ("trials", "subjects"):
            load_schema(name)
    except Exception:
        failed.append("workflow/schemas")
    return failed


def _request(conn: socket.socket) -> tuple[dict, list[int]]:
    """The client's request (4-byte length first, then a marshal-ed dict: the client is run
    by this same interpreter, and marshal is built in, where json would cost every job's
    client ~20 ms of imports) and the descriptors sent with it."""
    buf, fds, _flags, _addr = socket.recv_fds(conn, 65536, 3)
    fds = list(fds)
    while len(buf) < 4 or len(buf) < 4 + struct.unpack("!I", buf[:4])[0]:
        chunk = conn.recv(65536)
        if not chunk:
            raise ConnectionError("the client closed the connection mid-request")
        buf += chunk
    (n,) = struct.unpack("!I", buf[:4])
    return marshal.loads(buf[4:4 + n]), fds


_ANSWERED = threading.Event()


def _watch(conn: socket.socket) -> None:
    """In the child: the client went away before the answer → stop the job."""
    try:
        gone = conn.recv(1) == b""
    except OSError:
        gone = True
    if gone and not _ANSWERED.is_set():        # the job and whatever it started
        try:
            os.killpg(0, signal.SIGKILL)
        finally:
            os._exit(137)


def _run_job(conn: socket.socket) -> None:
    """In the forked child: become the job, run it, answer the exit code; never returns."""
    rc = 1
    try:
        os.setpgid(0, 0)                       # its own group: cancelling ends it all
        for s in (signal.SIGTERM, signal.SIGHUP):
            signal.signal(s, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        req, fds = _request(conn)
        print(f"job {os.getpid()}: gaitval {' '.join(req['argv'])}", flush=True)   # server log
        for i, fd in enumerate(fds[:3]):
            os.dup2(fd, i)
            os.close(fd)
        os.chdir(req["cwd"])
        os.environ.clear()
        os.environ.update(req["env"])
        conn.sendall(struct.pack("!i", os.getpid()))
        threading.Thread(target=_watch, args=(conn,), daemon=True).start()
        sys.argv = ["gaitval", *req["argv"]]
        from gaitval.cli import main
        try:
            rc = main(req["argv"])
        except SystemExit as exc:              # argparse usage errors, sys.exit in a verb
            code = exc.code
            if code is None:
                rc = 0
            elif isinstance(code, int):
                rc = code
            else:
                print(code, file=sys.stderr)
                rc = 1
    except BaseException:                      # noqa: BLE001 - report, never hang the client
        traceback.print_exc()
        rc = 1
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except Exception:
                pass
    _ANSWERED.set()                            # the client may now close: not a cancel
    try:
        conn.sendall(struct.pack("!i", int(rc or 0)))
    finally:
        os._exit(int(rc or 0) & 0xFF)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _reap(jobs: dict[int, float]) -> None:
    """Collect finished jobs; log each one's wall and CPU seconds (user + system)."""
    while jobs:
        try:
            pid, status, ru = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        t0 = jobs.pop(pid, None)
        if t0 is not None:
            print(f"job {pid}: exit {os.waitstatus_to_exitcode(status)}, "
                  f"wall {time.perf_counter() - t0:.3f} s, "
                  f"cpu {ru.ru_utime + ru.ru_stime:.3f} s", flush=True)


def serve(path: str, owner: int | None) -> int:
    stop = []
    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, lambda signum, _f: stop.append(signum))
    old = os.umask(0o077)
    try:
        os.makedirs(os.path.dirname(path), mode=0o700, exist_ok=True)
        if os.path.exists(path):
            os.unlink(path)
        srv = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        srv.bind(path)
    finally:
        os.umask(old)
    srv.listen(64)
    srv.settimeout(0.5)
    print(f"gaitval fork server: pid {os.getpid()} on {path}", flush=True)
    jobs: dict[int, float] = {}
    try:
        while not stop and (owner is None or _alive(owner)):
            _reap(jobs)
            try:
                conn, _ = srv.accept()
            except (socket.timeout, InterruptedError):
                continue
            conn.settimeout(None)
            sys.stdout.flush()
            sys.stderr.flush()
            pid = os.fork()
            if pid == 0:
                srv.close()
                _run_job(conn)
            jobs[pid] = time.perf_counter()
            conn.close()
    finally:
        srv.close()
        try:
            os.unlink(path)
        except FileNotFoundError:
            pass
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m gaitval.forkserver",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("--socket", required=True, help="Unix socket path to listen on")
    ap.add_argument("--owner", type=int, default=None,
                    help="exit when the process with this pid is gone")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    failed = preload()
    gc.freeze()          # the preloaded objects: the children's collections skip them and so
    #                      leave their pages shared instead of copying them on the first gc
    print(f"gaitval fork server: imports took {time.perf_counter() - t0:.2f} s"
          + (f"; not importable (jobs needing them will say so): {', '.join(failed)}"
             if failed else ""), flush=True)
    return serve(a.socket, a.owner)


if __name__ == "__main__":
    sys.exit(main())
