# The warm fork server of local runs (gaitval/forkserver.py; FORK_SERVER in common.smk):
# started when the run starts, stopped when it ends.  It also exits by itself when this
# Snakemake process is gone (a killed run leaves nothing behind).  Its log:
# logs/forkserver.log.
import os
import signal
import subprocess

_FORK_SERVER_PROC = []


def _fork_server_workers():
    """One worker per job Snakemake runs at once: its --cores (at least 1)."""
    try:
        return max(1, int(workflow.cores))
    except Exception:                 # cores not set (WorkflowError) or not a number
        return 2


def _start_fork_server():
    Path("logs").mkdir(exist_ok=True)
    log = open("logs/forkserver.log", "w")
    _FORK_SERVER_PROC.append(
        subprocess.Popen(
            [sys.executable, "-m", "gaitval.forkserver", "--socket", FORK_SOCKET,
             "--owner", str(os.getpid()), "--workers", str(_fork_server_workers())],
            stdout=log, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
            start_new_session=True,
        )
    )
    # Not waited for: until its imports are done (a few seconds) jobs run the plain way.


def _stop_fork_server():
    for proc in _FORK_SERVER_PROC:
        if proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
    _FORK_SERVER_PROC.clear()


def _pass_interrupt_to_fork_jobs():
    """Ctrl-C reaches a shell job through the terminal's process group; a job sent to the
    fork server from Snakemake's thread (common.smk) runs in a worker of its own group, so
    Snakemake's SIGINT handler passes the signal on to those workers first -- the jobs stop
    at once instead of running to their end while Snakemake waits for them."""
    previous = signal.getsignal(signal.SIGINT)
    if not callable(previous):                # ignored (e.g. a background job): leave it
        return

    def handler(signum, frame):
        for pid in list(FORK_JOBS):
            try:
                os.killpg(pid, signum)
            except (ProcessLookupError, PermissionError):
                pass
        previous(signum, frame)

    signal.signal(signal.SIGINT, handler)


if FORK_SERVER:

    onstart:
        # only the Snakemake process that runs the jobs here (not a cluster executor's,
        # whose jobs run elsewhere, nor a job's own Snakemake on a node)
        if workflow.local_exec and not workflow.remote_exec:
            _start_fork_server()
            _pass_interrupt_to_fork_jobs()

    onsuccess:
        _stop_fork_server()

    onerror:
        _stop_fork_server()
