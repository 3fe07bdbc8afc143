"""The warm fork server (gaitval/forkserver.py) runs a verb exactly as the plain command does.

What a user relies on: the same output, log text and exit code as ``python -m gaitval``; a
job that finds no server still runs; a cancelled job does not keep running.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CLIENT = ROOT / "gaitval" / "forkclient.py"


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    sock = tmp_path_factory.mktemp("fs") / "s.sock"
    proc = subprocess.Popen([sys.executable, "-m", "gaitval.forkserver", "--socket", str(sock),
                             "--owner", str(os.getpid())], cwd=ROOT,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    for _ in range(600):
        if sock.exists() or proc.poll() is not None:
            break
        time.sleep(0.1)
    assert sock.exists(), f"fork server did not start: {proc.stdout.read() if proc.poll() is not None else ''}"
    yield sock
    proc.send_signal(signal.SIGTERM)
    proc.wait(timeout=20)
    assert not sock.exists(), "the server removes its socket when it stops"


def _client(sock, *args, cwd=ROOT, **kw):
    return subprocess.run([sys.executable, "-I", "-S", str(CLIENT), str(sock), "--", *args],
                          cwd=cwd, capture_output=True, text=True, timeout=120, **kw)


def _plain(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "gaitval", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)


def test_same_output_and_exit_code_as_the_plain_command(server, tmp_path):
    bad = tmp_path / "broken.c3d"
    bad.write_bytes(b"\x02\x50" + b"\x00" * 100)
    for args in (["--version"], ["inspect", str(bad)], ["inspect", str(tmp_path / "none.c3d")],
                 ["no-such-verb"]):
        a, b = _client(server, *args), _plain(*args)
        assert (a.returncode, a.stdout) == (b.returncode, b.stdout), args
        assert a.stderr.replace("__main__.py", "gaitval") == \
            b.stderr.replace("__main__.py", "gaitval"), args
    assert _client(server, "inspect", str(bad)).returncode == 1


def test_relative_paths_resolve_in_the_clients_folder(server, tmp_path):
    (tmp_path / "sub").mkdir()
    out = _client(server, "simulate", "--preset", "nonexistent-preset", "--out", "sub/x",
                  cwd=tmp_path)
    ref = _plain("simulate", "--preset", "nonexistent-preset", "--out", "sub/x", cwd=tmp_path)
    assert out.returncode == ref.returncode != 0
    assert out.stderr == ref.stderr


def test_without_a_server_the_plain_command_runs(tmp_path):
    r = _client(tmp_path / "no.sock", "--version")
    assert r.returncode == 0 and r.stdout.startswith("gaitval ")


def test_a_cancelled_job_stops(server, tmp_path):
    """Killing the client (Snakemake cancelling the job) ends the job: the worker that ran it
    and every process it started; the server replaces the worker."""
    idle = _children_of_server(server)
    assert len(idle) == 2, "two warm workers wait for jobs"
    # a verb that takes a while: simulate the default preset (about 10 s on two cores)
    proc = subprocess.Popen([sys.executable, "-I", "-S", str(CLIENT), str(server), "--",
                             "simulate", "--out", str(tmp_path / "study")], cwd=ROOT,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(3)
    busy = max(_children_of_server(server),
               key=lambda w: sum(_cpu_ticks(p) for p in _group_of(w)))
    group = _group_of(busy)
    assert busy in idle and sum(_cpu_ticks(p) for p in group) > 50, \
        "the job runs in one of the warm workers (and the processes it started)"
    proc.kill()                                  # SIGKILL: the client cannot pass it on
    proc.wait()
    deadline = time.time() + 20
    while time.time() < deadline and any(_alive(p) for p in group):
        time.sleep(0.2)
    assert not any(_alive(p) for p in group), "the job's worker and its processes are gone"
    while time.time() < deadline and len(_children_of_server(server)) < 2:
        time.sleep(0.2)
    fresh = _children_of_server(server)
    assert len(fresh) == 2 and busy not in fresh, "a fresh worker took its place"
    r = _client(server, "--version")
    assert r.returncode == 0 and r.stdout.startswith("gaitval ")


def test_a_worker_runs_many_jobs_each_as_a_fresh_process_would(server, tmp_path):
    """Jobs share a warm worker; what one job sets (environment, folder, warnings shown once)
    does not reach the next: the same command four times gives the plain command's output
    four times (a failed job's worker is replaced by a fresh one)."""
    bad = tmp_path / "broken.c3d"
    bad.write_bytes(b"\x02\x50" + b"\x00" * 100)
    ref = _plain("inspect", str(bad), cwd=tmp_path)
    for _ in range(4):
        r = _client(server, "inspect", "broken.c3d", cwd=tmp_path)
        assert (r.returncode, r.stdout) == (ref.returncode, ref.stdout)
        assert r.stderr.replace(str(tmp_path) + "/", "") == \
            ref.stderr.replace(str(tmp_path) + "/", "")
    time.sleep(0.5)                              # failed jobs' workers were replaced
    before = _children_of_server(server)
    for _ in range(6):
        assert _client(server, "--version").returncode == 0
    assert _children_of_server(server) == before, \
        "a worker that ran a job successfully stays for the next"


def _children_of_server(sock) -> list[int]:
    procs = {}
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                args = (d / "cmdline").read_bytes().replace(b"\0", b" ").decode()
                ppid = int((d / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            procs[int(d.name)] = (ppid, args)
    srv = [p for p, (_pp, a) in procs.items() if "gaitval.forkserver" in a and str(sock) in a]
    return [p for p, (pp, _a) in procs.items() if srv and pp == srv[0]]


def _stat(pid: int) -> list[str]:
    return (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()


def _cpu_ticks(pid: int) -> int:
    """utime + stime of a process, clock ticks (0 when it is gone)."""
    try:
        f = _stat(pid)
    except (OSError, IndexError):
        return 0
    return int(f[11]) + int(f[12])


def _group_of(pid: int) -> list[int]:
    """The processes of pid's process group (the worker leads its own)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                if int(_stat(int(d.name))[2]) == pid:
                    out.append(int(d.name))
            except (OSError, ValueError, IndexError):
                continue
    return out


def _alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().split()[2] != "Z"
    except FileNotFoundError:
        return False


def test_what_a_job_changes_in_its_worker_is_put_back(tmp_path, monkeypatch):
    """The worker's own bookkeeping, driven directly: a job that changes the environment,
    folder, numpy's error handling, a signal handler, sys.stdout and the warning filters
    leaves none of it to the next job, and its exit code reaches the client."""
    import array
    import io
    import marshal
    import socket
    import struct
    import warnings

    import numpy as np

    from gaitval import forkserver as fsv

    def job(argv):
        os.environ["GAITVAL_LEAK"] = "1"
        os.chdir(tmp_path)
        np.seterr(all="raise")
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        sys.stdout = io.StringIO()
        warnings.simplefilter("error")
        return 3

    monkeypatch.setattr(fsv, "_call_main", job)
    state = lambda: (os.getcwd(), dict(os.environ), np.geterr(),  # noqa: E731
                     signal.getsignal(signal.SIGTERM), sys.stdout, list(warnings.filters))
    before = state()
    client, worker = socket.socketpair()
    body = marshal.dumps({"argv": ["verb"], "cwd": str(ROOT), "env": dict(os.environ)})
    logr, logw = os.pipe()
    with open(os.devnull, "r+b") as nul:
        client.sendmsg([struct.pack("!I", len(body)) + body],
                       [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", [nul.fileno()] * 3))])
        rc = fsv._serve_one(worker, "test.1", logw)
    assert state() == before
    assert rc == 3
    assert struct.unpack("!ii", client.recv(8)) == (os.getpid(), 3)
    os.close(logw)
    log = os.read(logr, 4096).decode()
    assert log.startswith("job test.1: gaitval verb\njob test.1: exit 3, wall ")
