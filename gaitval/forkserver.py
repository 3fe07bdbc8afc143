"""A warm process for many short ``gaitval`` jobs: import once, run each job in a warm worker
(issue 13).

A local workflow run is hundreds of short jobs (ingest, register, track, evaluate per
trial).  Started as ``python -m gaitval VERB ...`` each one spends 0.7–1.9 CPU-s importing
numpy, pandas, pyarrow, scipy and gaitval before ~0.05–0.6 s of work.  The server imports all
of that once, then forks ``--workers`` worker processes (one per core of the run) that share
its listening socket; each worker takes one job at a time and runs
``gaitval.cli.main(args)`` in itself — the same function, the same arguments, the same files
as the plain command, so outputs are byte-identical.  Snakemake still sees one job per trial
(its DAG, reruns and logs are unchanged); on a cluster, where no server runs,
:mod:`gaitval.forkclient` falls back to the plain command.

Why workers that live across jobs rather than a fork per job: a job forked from the
server pays for its copy-on-write page faults (~7,000–18,000 per job, the pages of
pandas/numpy/gaitval objects it touches) and for its allocator's first pages: measured
0.04–0.2 CPU-s more per job than the same call in a warm process (`register` 0.28 against
0.19 s), about 60 CPU-s over the default report.  A worker keeps its pages.

What a job could leave behind for the next is reset after each: standard streams (the
descriptors and the ``sys.std*`` objects are put back), working directory, environment,
``sys.argv``, signal handlers, numpy's error handling, warning filters and the "shown once"
registry (each job runs under ``warnings.catch_warnings()``, so a warning appears in every
job's log, as in a fresh process), open matplotlib figures.  A worker
that ran a job which failed (exit code not 0), that ran ``--max-jobs`` jobs, or whose peak
memory passed ``--max-rss-mb`` exits after answering, and the server forks a fresh one.

Lifecycle (``Snakefile``: ``onstart`` / ``onsuccess`` / ``onerror`` when the config's
``fork_server`` is true): started with the Snakemake process's pid as ``--owner``; it exits
when that process is gone (a killed run leaves no server behind), on SIGTERM, or on SIGINT,
stops its workers and removes its socket.  The socket lives in a private directory (mode
0700) under the temporary directory, so only the same user can submit jobs.

Protocol (Unix stream socket): the client sends a 4-byte length and a marshal-ed object
``{"argv", "cwd", "env", "via"}`` with its stdin/stdout/stderr attached (SCM_RIGHTS); a worker
(leader of its own process group) answers its pid (4 bytes), runs the verb with those
descriptors, working directory and environment, and answers the exit code (4 bytes).  A
client that disconnects before the end (the job was cancelled) has its worker's process
group killed; the server replaces the worker.

Log (the server's standard output, ``logs/forkserver.log`` in a workflow run): per job
``job <worker pid>.<n>: gaitval ARGS`` when it starts and ``job <worker pid>.<n>: exit <rc>,
wall <s> s, cpu <s> s, worker peak <MB> MB, via <sender>`` when it ends (CPU of the worker
and the processes it waited for; the worker's peak resident memory so far; ``client`` for
:mod:`gaitval.forkclient` run as a process, ``snakemake`` for a job sent from Snakemake's
own job thread by the workflow, see ``workflow/rules/common.smk``).

Usage::

    python -m gaitval.forkserver --socket PATH --owner PID [--workers N]
"""
from __future__ import annotations

import argparse
import gc
import importlib
import marshal
import os
import pkgutil
import resource
import signal
import socket
import struct
import sys
import threading
import time
import traceback
import warnings

from gaitval.forkclient import folder_problem

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
    try:                                       # the CLI's parser, built once for all jobs
        from gaitval.cli import parser
        parser()
    except Exception:
        failed.append("gaitval.cli.parser")
    for name in ("gaitval.track.pf", "gaitval.track.ukf"):
        try:                                   # the PF's and the UKF's compiled kernels,
            importlib.import_module(name).warm_up()   # loaded (or compiled) once for all
        except Exception:                      # workers
            failed.append(f"{name}.warm_up")
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


def _watch(conn: socket.socket, done: threading.Event) -> None:
    """While a job runs: the client went away before the answer → stop the job (this
    worker's process group; the server forks a new worker)."""
    try:
        gone = conn.recv(1) == b""
    except OSError:
        gone = True
    if gone and not done.is_set():
        try:
            os.killpg(0, signal.SIGKILL)
        finally:
            os._exit(137)


def _call_main(argv: list[str]) -> int:
    from gaitval.cli import main
    try:
        return int(main(argv) or 0)
    except SystemExit as exc:                  # argparse usage errors, sys.exit in a verb
        code = exc.code
        if code is None:
            return 0
        if isinstance(code, int):
            return code
        print(code, file=sys.stderr)
        return 1


def _cpu() -> float:
    me, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(
        resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime


def _peak_mb() -> float:
    """This process's peak resident memory so far, MB."""
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def _log(fd: int, line: str) -> None:
    os.write(fd, (line + "\n").encode())


_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP, signal.SIGPIPE, signal.SIGCHLD)


def _np_errstate() -> dict | None:
    """numpy's floating-point error handling (``np.seterr``), which a job could change."""
    np = sys.modules.get("numpy")
    return None if np is None else np.geterr()


def _tidy() -> None:
    """What a job may leave open in the process: matplotlib figures."""
    plt = sys.modules.get("matplotlib.pyplot")
    if plt is not None:
        plt.close("all")


def _serve_one(conn: socket.socket, jid: str, logfd: int) -> int:
    """In a worker: run one client's job with its descriptors, folder and environment, answer
    its exit code, and put the process back as it was.  Returns the exit code."""
    t0, c0 = time.perf_counter(), _cpu()
    rc = 1
    done = threading.Event()
    watcher = None
    cwd, env, argv0 = os.getcwd(), dict(os.environ), list(sys.argv)
    streams = (sys.stdin, sys.stdout, sys.stderr)
    handlers = {sig: signal.getsignal(sig) for sig in _SIGNALS}
    np_err = _np_errstate()
    saved = [os.dup(i) for i in range(3)]
    via = "client"
    try:
        req, fds = _request(conn)
        via = str(req.get("via", via))
        _log(logfd, f"job {jid}: gaitval {' '.join(req['argv'])}")
        for i, fd in enumerate(fds[:3]):
            os.dup2(fd, i)
        for fd in fds:
            os.close(fd)
        os.chdir(req["cwd"])
        os.environ.clear()
        os.environ.update(req["env"])
        conn.sendall(struct.pack("!i", os.getpid()))
        watcher = threading.Thread(target=_watch, args=(conn, done), daemon=True)
        watcher.start()
        sys.argv = ["gaitval", *req["argv"]]
        with warnings.catch_warnings():        # filters back after; "once" shown again
            rc = _call_main(req["argv"])
    except BaseException:                      # noqa: BLE001 - report, never hang the client
        traceback.print_exc()
        rc = 1
    finally:
        # the job's streams and the worker's own (a job may have replaced sys.stdout):
        # everything buffered goes to the job's log before its descriptors are put back
        for stream in (sys.stdout, sys.stderr, *streams[1:]):
            try:
                stream.flush()
            except Exception:
                pass
        done.set()                             # the client may now close: not a cancel
        try:
            conn.sendall(struct.pack("!i", int(rc)))
        except OSError:
            pass
        try:
            conn.shutdown(socket.SHUT_RDWR)    # wakes the watcher's recv
        except OSError:
            pass
        if watcher is not None:
            watcher.join(timeout=5)
        conn.close()
        for i, fd in enumerate(saved):
            os.dup2(fd, i)
            os.close(fd)
        sys.stdin, sys.stdout, sys.stderr = streams
        for sig, handler in handlers.items():
            if handler is not None:
                signal.signal(sig, handler)
        if np_err is not None:
            sys.modules["numpy"].seterr(**np_err)
        sys.argv = argv0
        os.environ.clear()
        os.environ.update(env)
        os.chdir(cwd)
        try:
            _tidy()
        except Exception:                      # noqa: BLE001 - next job gets a fresh worker
            rc = rc or 1
    _log(logfd, f"job {jid}: exit {rc}, wall {time.perf_counter() - t0:.3f} s, "
                f"cpu {_cpu() - c0:.3f} s, worker peak {_peak_mb():.0f} MB, via {via}")
    return rc


def _worker(srv: socket.socket, master: int, max_jobs: int, max_rss_mb: float) -> None:
    """A worker's life: take jobs from the shared socket until it should make way for a
    fresh one (see the module's docstring) or the server is gone; never returns."""
    try:
        os.setpgid(0, 0)                       # its own group: cancelling a job ends it all
        for s in (signal.SIGTERM, signal.SIGHUP):
            signal.signal(s, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        logfd = os.dup(1)                      # the server's log (fd 1 becomes each job's)
        n = 0
        while n < max_jobs and os.getppid() == master:
            try:
                conn, _ = srv.accept()
            except (socket.timeout, BlockingIOError, InterruptedError):
                continue
            conn.settimeout(None)
            n += 1
            rc = _serve_one(conn, f"{os.getpid()}.{n}", logfd)
            if rc != 0 or _peak_mb() > max_rss_mb:
                break
    except BaseException:                      # noqa: BLE001
        traceback.print_exc()
    finally:
        os._exit(0)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def serve(path: str, owner: int | None, workers: int = 2, max_jobs: int = 2000,
          max_rss_mb: float = 2048.0) -> int:
    stop = []
    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, lambda signum, _f: stop.append(signum))
    old = os.umask(0o077)
    try:
        os.makedirs(os.path.dirname(path), mode=0o700, exist_ok=True)
        why = folder_problem(path)          # made by someone else before us, or loosened
        if why is not None:
            print(f"gaitval fork server: error: refusing the socket folder "
                  f"{os.path.dirname(os.path.abspath(path))}: {why}; remove it (or fix it: "
                  "chmod 700, owned by you) and start again", file=sys.stderr, flush=True)
            return 1
        if os.path.exists(path):
            os.unlink(path)
        srv = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        srv.bind(path)
    finally:
        os.umask(old)
    srv.listen(64)
    srv.settimeout(0.5)                        # the workers' accept checks the server is there
    print(f"gaitval fork server: pid {os.getpid()} on {path}, {workers} workers", flush=True)
    me = os.getpid()
    pool: set[int] = set()

    def spawn() -> None:
        sys.stdout.flush()
        sys.stderr.flush()
        pid = os.fork()
        if pid == 0:
            _worker(srv, me, max_jobs, max_rss_mb)
        pool.add(pid)

    try:
        for _ in range(max(1, workers)):
            spawn()
        while not stop and (owner is None or _alive(owner)):
            while True:                        # a worker that ended makes way for a fresh one
                try:
                    pid, _status = os.waitpid(-1, os.WNOHANG)
                except ChildProcessError:
                    pid = 0
                if pid == 0:
                    break
                pool.discard(pid)
            while not stop and len(pool) < max(1, workers):
                spawn()
            time.sleep(0.05)
    finally:
        for pid in pool:
            try:
                os.killpg(pid, signal.SIGTERM)
            except (ProcessLookupError, PermissionError):
                pass
        for pid in pool:
            try:
                os.waitpid(pid, 0)
            except ChildProcessError:
                pass
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
    ap.add_argument("--workers", type=int, default=2,
                    help="worker processes, i.e. jobs run at once (the run's cores; default 2)")
    ap.add_argument("--max-jobs", type=int, default=2000,
                    help="a worker makes way for a fresh one after this many jobs")
    ap.add_argument("--max-rss-mb", type=float, default=2048.0,
                    help="... or once its peak memory passed this many MB")
    a = ap.parse_args(argv)
    t0 = time.perf_counter()
    from gaitval.io.filememo import set_cap, worker_budget_mb
    set_cap(worker_budget_mb(a.workers))       # what a worker may keep of the files it read
    failed = preload()
    gc.freeze()          # the preloaded objects: the workers' collections skip them and so
    #                      leave their pages shared instead of copying them on the first gc
    print(f"gaitval fork server: imports took {time.perf_counter() - t0:.2f} s"
          + (f"; not importable (jobs needing them will say so): {', '.join(failed)}"
             if failed else ""), flush=True)
    return serve(a.socket, a.owner, a.workers, a.max_jobs, a.max_rss_mb)


if __name__ == "__main__":
    sys.exit(main())
