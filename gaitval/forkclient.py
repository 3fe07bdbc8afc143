"""Run one ``gaitval`` verb in the warm fork server, or start it the plain way.

Usage (what the workflow's rules run when ``fork_server`` is on, see
:mod:`gaitval.forkserver`)::

    python -I -S gaitval/forkclient.py SOCKET -- VERB [ARGS...]

This file is run as a script and imports only C modules of the standard library (``_socket``,
``_signal``, ``marshal``) and ``os``, so it starts in about 20 ms: it runs once per
job, ~1,100 times in the default report, where ``json``, ``socket`` and ``signal`` (which pull
in ``re`` and ``enum``) cost ~30 ms more each time.  It hands its working directory, environment, argument list and its
standard input/output/error (the job's log) to the server, where a warm worker that already
has numpy, pandas, pyarrow, scipy and gaitval imported runs ``gaitval.cli.main(args)`` —
the same code a plain ``python -m gaitval VERB ARGS`` runs — and the client exits with its
exit code.

* No server at SOCKET (a cluster node, a run without the server): the client replaces
  itself with ``python -m gaitval VERB ARGS`` — same result, the usual start-up cost.
* The client is stopped (Snakemake cancels the job): the signal is passed on to the
  worker's process group, and a worker whose client vanished (SIGKILL) stops itself; the
  server starts a fresh worker in its place.
"""
from __future__ import annotations

import _signal
import _socket
import marshal
import os
import sys


#: SCM_RIGHTS data: the C ints 0, 1, 2 (stdin, stdout, stderr) in native byte order -- what
#: ``array.array("i", [0, 1, 2])`` gives, without ``array``, whose import (it loads
#: ``collections``) costs ~2 ms of the client's ~10 ms, once per job.
_FDS = b"".join(fd.to_bytes(4, sys.byteorder, signed=True) for fd in (0, 1, 2))


def _plain(args: list[str]) -> None:
    os.execv(sys.executable, [sys.executable, "-m", "gaitval", *args])


def folder_problem(path: str) -> str | None:
    """Why the folder of the socket ``path`` is not safe to use, or None.

    The folder (``/tmp/gaitval-<uid>`` by default, workflow/rules/common.smk) lies in a
    directory anyone can write to: another user who created it first could listen on the
    socket and receive every job's environment and file descriptors.  So it must be a real
    directory (not a symbolic link), owned by this user, with no access for group or
    others (mode 0700).  Only ``os`` is used (this module's start-up budget)."""
    folder = os.path.dirname(os.path.abspath(path))
    try:
        st = os.lstat(folder)
    except OSError as exc:
        return f"cannot inspect it ({exc.strerror})"
    if (st.st_mode & 0o170000) != 0o040000:
        return "it is not a directory (a symbolic link or another file)"
    if st.st_uid != os.getuid():
        return f"it belongs to uid {st.st_uid}, not to this user (uid {os.getuid()})"
    if st.st_mode & 0o077:
        return (f"its mode is {st.st_mode & 0o777:04o}; group and others must have no "
                "access (0700)")
    return None


def _recv_int(sock: _socket.socket) -> int | None:
    buf = b""
    while len(buf) < 4:
        chunk = sock.recv(4 - len(buf))
        if not chunk:
            return None
        buf += chunk
    return int.from_bytes(buf, "big", signed=True)          # the server's struct "!i"


def submit(path: str, args: list[str], *, cwd: str, env: dict, fds: bytes = _FDS,
           on_start=None, via: str = "client") -> int | None:
    """Run ``gaitval ARGS`` in the server at ``path``; its exit code, or None when no server
    listens there (the caller then runs the plain command).

    ``fds``: the job's stdin, stdout and stderr descriptors as C ints (see ``_FDS``), handed
    over with SCM_RIGHTS.  ``via`` names the sender in the server's log.  ``on_start(pid)``
    is called with the worker's pid (the leader of its process group) once it has taken the
    job.  A connection the server closes gives 1 with the reason on this process's standard
    error.  Used by :func:`main` (one job per process) and by the workflow's ``shell``
    (workflow/rules/common.smk), which calls it from Snakemake's own job thread, so a local
    job starts no shell and no client.  A socket whose folder is unsafe
    (:func:`folder_problem`) is never connected to: a warning, then None.
    """
    if not os.path.exists(path):
        return None
    why = folder_problem(path)
    if why is not None:
        sys.stderr.write(f"gaitval: warning: not using the fork server at {path}: its folder "
                         f"is unsafe ({why}); running the plain command\n")
        return None
    sock = _socket.socket(_socket.AF_UNIX, _socket.SOCK_STREAM)
    try:
        try:
            sock.connect(path)
        except OSError:
            return None
        # marshal: the server runs this same interpreter (forkserver._request)
        body = marshal.dumps({"argv": list(args), "cwd": cwd, "env": dict(env), "via": via})
        msg = len(body).to_bytes(4, "big") + body
        sent = sock.sendmsg([msg], [(_socket.SOL_SOCKET, _socket.SCM_RIGHTS, fds)])
        if sent < len(msg):
            sock.sendall(msg[sent:])
        child = _recv_int(sock)
        if child is None:
            sys.stderr.write("gaitval: error: the fork server closed the connection\n")
            return 1
        if on_start is not None:
            on_start(child)
        rc = _recv_int(sock)
        if rc is None:
            sys.stderr.write("gaitval: error: the job's process ended without an exit code "
                             "(killed or crashed)\n")
            return 1
        return rc
    finally:
        sock.close()


def main(argv: list[str]) -> int:
    if len(argv) < 2 or argv[1] != "--":
        sys.stderr.write("usage: forkclient.py SOCKET -- VERB [ARGS...]\n")
        return 2
    path, args = argv[0], argv[2:]

    def forward_to(child):
        def forward(signum, _frame):
            try:
                os.killpg(child, signum)       # the worker's process group (see forkserver)
            except ProcessLookupError:
                pass
            raise SystemExit(128 + signum)

        for s in (_signal.SIGTERM, _signal.SIGINT, _signal.SIGHUP):
            _signal.signal(s, forward)

    rc = submit(path, args, cwd=os.getcwd(), env=os.environ, on_start=forward_to)
    if rc is None:
        _plain(args)                       # no server: the plain way (does not return)
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
