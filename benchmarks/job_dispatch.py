"""What it costs to hand one job to the warm fork server, two ways (issue 13).

Usage::

    .venv/bin/python benchmarks/job_dispatch.py [--jobs 150] [--rounds 2]

Starts a fork server (``python -m gaitval.forkserver``, one worker) on a private socket and
runs the same trivial job (``gaitval --version``, ~1 ms in the worker) ``--jobs`` times:

* ``shell``: as a Snakemake ``shell:`` job does -- ``bash -c "set -euo pipefail; <python>
  -I -S gaitval/forkclient.py SOCKET -- --version > log 2>&1 || (cat log >&2; exit 1)"``;
* ``direct``: as the workflow's ``shell`` does for a local job (workflow/rules/common.smk):
  :func:`gaitval.forkclient.submit` from the calling process, the log's descriptor handed
  over.

Each round runs both, alternated.  CPU is the calling process's plus its children's
(bash, the client; not the worker's, the same both ways).  The last line is exactly
``job dispatch: shell <ms> ms cpu, direct <ms> ms cpu per job`` (medians over rounds).
"""
from __future__ import annotations

import argparse
import os
import resource
import shlex
import statistics
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
CLIENT = ROOT / "gaitval" / "forkclient.py"


def _cpu() -> float:
    a, b = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return a.ru_utime + a.ru_stime + b.ru_utime + b.ru_stime


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=150)
    ap.add_argument("--rounds", type=int, default=2)
    args = ap.parse_args()
    from gaitval.forkclient import submit

    with tempfile.TemporaryDirectory() as tmp:
        sock, log = Path(tmp) / "s.sock", Path(tmp) / "job.log"
        server = subprocess.Popen([sys.executable, "-m", "gaitval.forkserver", "--socket",
                                   str(sock), "--owner", str(os.getpid()), "--workers", "1"],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT)
        try:
            for _ in range(600):
                if sock.exists():
                    break
                time.sleep(0.1)
            else:
                sys.exit("the fork server did not start")
            q = shlex.quote
            cmd = (f"set -euo pipefail; {q(sys.executable)} -I -S {q(str(CLIENT))} {q(str(sock))}"
                   f" -- --version > {q(str(log))} 2>&1 || (cat {q(str(log))} >&2; exit 1)")

            def shell_job():
                if subprocess.run(cmd, shell=True, executable="/bin/bash").returncode:
                    sys.exit("shell job failed")

            def direct_job():
                out = os.open(log, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_CLOEXEC, 0o666)
                nul = os.open(os.devnull, os.O_RDONLY | os.O_CLOEXEC)
                try:
                    rc = submit(str(sock), ["--version"], cwd=os.getcwd(), env=os.environ,
                                fds=struct.pack("3i", nul, out, out), via="benchmark")
                finally:
                    os.close(nul)
                    os.close(out)
                if rc != 0:
                    sys.exit(f"direct job failed ({rc})")

            per = {"shell": [], "direct": []}
            for r in range(args.rounds):
                for name, job in (("shell", shell_job), ("direct", direct_job)):
                    c, t = _cpu(), time.perf_counter()
                    for _ in range(args.jobs):
                        job()
                    cpu_ms = (_cpu() - c) / args.jobs * 1000
                    wall_ms = (time.perf_counter() - t) / args.jobs * 1000
                    per[name].append(cpu_ms)
                    print(f"round {r + 1} {name:6s}: {cpu_ms:6.2f} ms cpu, {wall_ms:6.2f} ms wall "
                          f"per job ({args.jobs} jobs)")
        finally:
            server.terminate()
            server.wait(timeout=20)
    print(f"job dispatch: shell {statistics.median(per['shell']):.2f} ms cpu, direct "
          f"{statistics.median(per['direct']):.2f} ms cpu per job")


if __name__ == "__main__":
    main()
